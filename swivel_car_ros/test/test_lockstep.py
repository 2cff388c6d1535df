"""The lockstep protocol under a fake wall clock: each call is given its time in ns."""

import math

from builtin_interfaces.msg import Time
import pytest
from swivel_car_ros.lockstep import (
    ChainedAnswers, ChainEntry, Entry, REPUBLISH_PERIOD_NS, SimLockstep, SimTick, stamp_ns)

MS = 1_000_000  # [ns]
PERIOD = 10 * MS  # [ns] sim time of a control period
WAIT = SimTick(0, False, False)


def sim(timeout_ms=0, real_time_factor=0.0, paused=False) -> SimLockstep:
    lockstep = SimLockstep(PERIOD, timeout_ms * MS, real_time_factor, paused, now_ns=0)
    lockstep.published(0, now_ns=0)
    return lockstep


def test_stamps_are_whole_nanoseconds():
    assert stamp_ns(Time(sec=3, nanosec=20_000_001)) == 3_020_000_001


def test_the_sim_waits_for_the_command_of_its_state_and_advances_on_it():
    s = sim()
    assert s.tick(5 * MS) == WAIT
    assert not s.heard(PERIOD, now_ns=6 * MS)  # not the state it published
    assert not s.command_ready and s.tick(7 * MS) == WAIT
    assert s.heard(0, now_ns=8 * MS)  # its state's: advance now
    s.advanced(PERIOD, now_ns=8 * MS)
    assert not s.command_ready and s.tick(9 * MS) == WAIT
    assert s.heard(PERIOD, now_ns=10 * MS)


def test_a_command_heard_while_paused_is_taken_on_resuming():
    s = sim(paused=True)
    assert not s.heard(0, now_ns=MS) and s.command_ready
    assert s.tick(2 * MS) == WAIT
    assert s.set_paused(False, now_ns=3 * MS)  # resuming with the command there: advance
    assert not s.set_paused(True, now_ns=4 * MS)
    assert s.set_paused(False, now_ns=5 * MS)
    assert s.tick(6 * MS) == SimTick(1, False, False)


def test_pause_holds_the_sim_and_restarts_the_timeout():
    s = sim(timeout_ms=100)
    assert not s.set_paused(True, now_ns=90 * MS)
    assert s.tick(500 * MS) == WAIT  # paused: no timeout, no republish
    assert not s.set_paused(False, now_ns=500 * MS)
    assert s.tick(590 * MS) == SimTick(0, True, False)  # 90 ms since the resume: no timeout
    assert s.tick(601 * MS).timed_out


def test_a_run_for_some_periods_pauses_at_the_state_they_end_in():
    s = sim(paused=True)
    assert not s.heard(0, now_ns=MS)  # paused: the command waits
    assert s.run_for(2, now_ns=2 * MS)  # its command is there: advance now
    assert s.pause_at_ns == 2 * PERIOD
    s.advanced(PERIOD, now_ns=3 * MS)
    assert not s.paused and s.heard(PERIOD, now_ns=4 * MS)
    s.advanced(2 * PERIOD, now_ns=5 * MS)
    assert s.paused and s.pause_at_ns is None  # at the state of the last period
    assert not s.heard(2 * PERIOD, now_ns=6 * MS) and s.tick(7 * MS) == WAIT
    assert s.run_for(1, now_ns=8 * MS)  # the command came while paused: advance now
    assert s.pause_at_ns == 3 * PERIOD
    assert not s.set_paused(True, now_ns=9 * MS) and s.pause_at_ns is None  # ends the run
    with pytest.raises(ValueError, match='periods must be >= 1'):
        s.run_for(0, now_ns=10 * MS)


def test_while_waiting_the_state_is_published_again():
    s = sim()
    assert s.tick(REPUBLISH_PERIOD_NS) == WAIT
    assert s.tick(REPUBLISH_PERIOD_NS + 1) == SimTick(0, True, False)
    s.published(0, now_ns=REPUBLISH_PERIOD_NS + 1)
    assert s.tick(REPUBLISH_PERIOD_NS + 2) == WAIT
    assert s.tick(1_000_000 * MS) == SimTick(0, True, False)  # timeout 0: waits forever


def test_after_the_timeout_real_time_until_a_command_then_lockstep_again():
    s = sim(timeout_ms=100)
    assert s.tick(100 * MS) == WAIT
    assert s.tick(101 * MS) == SimTick(1, False, True)  # the controller is taken for gone
    s.advanced(PERIOD, now_ns=101 * MS)
    assert s.tick(105 * MS) == WAIT  # less than a period of wall time since
    assert s.tick(131 * MS) == SimTick(3, False, False)  # the periods due: real time
    for k in range(2, 5):
        s.advanced(k * PERIOD, now_ns=131 * MS)
    assert s.tick(1000 * MS).periods == 86  # no republish, no new timeout, however long
    for k in range(5, 91):
        s.advanced(k * PERIOD, now_ns=1000 * MS)
    # Any command, even one for a state long past, brings the waiting back.
    assert not s.heard(PERIOD, now_ns=1005 * MS)
    assert s.tick(1050 * MS) == WAIT
    assert s.tick(1101 * MS).timed_out  # measured from the last advance


def test_the_pace_cap_keeps_an_absolute_schedule():
    s = sim(real_time_factor=2.0)  # at least 5 ms of wall time per 10 ms period
    assert s.min_period_ns == 5 * MS and s.tick_period_ns == 2_500_000
    assert s.heard(0, now_ns=0)
    s.advanced(PERIOD, now_ns=0)
    assert not s.heard(PERIOD, now_ns=4 * MS)  # too early: the timer advances it when due
    assert s.tick(4_900_000) == WAIT
    assert s.tick(5 * MS) == SimTick(1, False, False)
    s.advanced(2 * PERIOD, now_ns=7 * MS)  # the timer came 2 ms late
    assert not s.heard(2 * PERIOD, now_ns=9 * MS)
    assert s.tick(10 * MS).periods == 1  # due at 10 ms, not 12: the lag does not add up
    s.advanced(3 * PERIOD, now_ns=40 * MS)  # far behind: the schedule restarts from now
    assert s.heard(3 * PERIOD, now_ns=45 * MS)


def test_the_timer_is_fine_enough_for_the_timeout_and_the_cap():
    assert sim().tick_period_ns == 20 * MS
    assert sim(timeout_ms=40).tick_period_ns == 10 * MS
    assert sim(timeout_ms=1000, real_time_factor=1.0).tick_period_ns == 5 * MS


def test_commands_older_than_a_reset_are_refused_and_a_step_moves_the_state():
    s = sim()
    for k in range(1, 4):
        s.advanced(k * PERIOD, now_ns=k * MS)
    assert s.accepts(3 * PERIOD)
    s.reset(4 * PERIOD, now_ns=5 * MS)
    assert not s.accepts(3 * PERIOD) and s.accepts(4 * PERIOD) and s.accepts(0)
    s.stepped(4 * PERIOD + 2 * MS)  # two physics steps into the period
    assert not s.heard(4 * PERIOD, now_ns=6 * MS)
    assert s.heard(4 * PERIOD + 2 * MS, now_ns=6 * MS)


class Controller:
    """What the controller node does with ChainedAnswers, recording the states it answers."""

    def __init__(self, swivel_command=True, cmd_vel=True):
        self.chain = ChainedAnswers(50 * MS, swivel_command, cmd_vel)
        self.holding = False
        self.answers = []
        self.repeated = []  # states answered again with the same command, and nothing else

    def answer(self, state):
        if state is None:
            return
        if self.chain.repeats(state):
            self.repeated.append(state)
            return
        self.chain.answered(state)
        self.answers.append(state)

    def state(self, t, now_ns=0):
        self.answer(self.chain.state(t, t, self.holding, now_ns))

    def swivel_command(self, t, hold=True, applied=True):
        if applied:
            self.holding = hold
        self.answer(self.chain.heard(self.chain.planner, t, applied, self.holding))

    def cmd_vel(self, t):
        self.answer(self.chain.heard(self.chain.driver, t, True, self.holding))

    def tick(self, now_ns):
        state, late = self.chain.tick(self.holding, now_ns)
        self.answer(state)
        return [source.name for source in late]


def planner_chained(**lockstep) -> Controller:
    """Return a controller whose planner answered the state of 1, then answered 2."""
    c = Controller(**lockstep)
    c.state(1 * PERIOD)  # nothing chained: answered at once
    c.swivel_command(1 * PERIOD)  # the planner answers it: now in the chain
    c.state(2 * PERIOD)
    return c


def test_a_held_stamped_swivel_command_makes_the_next_state_wait_for_its_answer():
    c = planner_chained()
    assert c.answers == [PERIOD, 2 * PERIOD]
    c.state(3 * PERIOD, now_ns=0)  # waits for the answer to 2
    assert c.answers[-1] == 2 * PERIOD
    assert c.tick(50 * MS) == [] and c.answers[-1] == 2 * PERIOD  # not yet late
    c.swivel_command(2 * PERIOD)
    assert c.answers[-1] == 3 * PERIOD
    c.state(3 * PERIOD)  # a republished state already answered: its command again
    assert c.answers == [PERIOD, 2 * PERIOD, 3 * PERIOD] and c.repeated == [3 * PERIOD]


def test_a_state_republished_after_its_answer_gets_its_command_again_and_nothing_more():
    c = planner_chained()
    c.state(3 * PERIOD, now_ns=0)
    c.swivel_command(2 * PERIOD)  # the state of 3 is answered
    c.swivel_command(3 * PERIOD)  # and the planner's answer to it comes, for the next
    # The sim published 3 again before the answer reached it: the copy comes after both.
    c.state(3 * PERIOD, now_ns=REPUBLISH_PERIOD_NS + 1)
    assert c.answers == [PERIOD, 2 * PERIOD, 3 * PERIOD] and c.repeated == [3 * PERIOD]
    c.state(4 * PERIOD, now_ns=REPUBLISH_PERIOD_NS + 2)  # the next moment: a new answer
    assert c.answers[-1] == 4 * PERIOD and c.repeated == [3 * PERIOD]
    assert not c.chain.repeats(3 * PERIOD) and c.chain.repeats(4 * PERIOD)


def test_a_command_for_another_state_does_not_release_the_wait():
    c = planner_chained()
    c.state(3 * PERIOD)
    c.swivel_command(1 * PERIOD)  # again the answer to 1: the state of 3 still waits
    assert c.answers[-1] == 2 * PERIOD


def test_a_source_that_does_not_answer_is_late_then_rechained_by_its_next_command():
    c = planner_chained()
    c.state(3 * PERIOD, now_ns=100 * MS)
    c.state(3 * PERIOD, now_ns=120 * MS)  # republished: the wait runs from the first
    assert c.tick(150 * MS) == []
    assert c.tick(151 * MS) == ['swivel_command']
    assert c.answers[-1] == 3 * PERIOD
    c.state(4 * PERIOD)  # late: not waited for
    assert c.answers[-1] == 4 * PERIOD
    c.swivel_command(4 * PERIOD)  # its next stamped command: in the chain again
    c.state(5 * PERIOD)
    c.state(6 * PERIOD)
    assert c.answers[-1] == 5 * PERIOD
    assert c.tick(10_000 * MS) == ['swivel_command']


def test_a_late_command_still_counts_once_it_comes():
    c = planner_chained()
    c.state(3 * PERIOD, now_ns=0)
    assert c.tick(51 * MS) == ['swivel_command']
    c.swivel_command(2 * PERIOD)  # the answer to 2, after 3 was answered without it
    c.state(4 * PERIOD)  # waits for the answer to 3
    assert c.answers[-1] == 3 * PERIOD


def test_the_driver_joins_with_a_stamped_cmd_vel_and_leaves_with_an_unstamped_one():
    c = Controller()
    c.state(1 * PERIOD)
    c.cmd_vel(1 * PERIOD)
    c.state(2 * PERIOD)
    c.state(3 * PERIOD)
    assert c.answers[-1] == 2 * PERIOD
    c.cmd_vel(0)  # a teleop's: out of the chain, and the pending state is answered
    assert c.answers[-1] == 3 * PERIOD
    assert c.chain.driver.heard_ns == PERIOD  # still the last stamped one
    c.state(4 * PERIOD)
    assert c.answers[-1] == 4 * PERIOD


def test_both_sources_are_waited_for_and_both_can_be_late():
    c = Controller()
    c.state(1 * PERIOD)
    c.swivel_command(1 * PERIOD)
    c.cmd_vel(1 * PERIOD)
    c.state(2 * PERIOD)
    c.state(3 * PERIOD)
    c.cmd_vel(2 * PERIOD)
    assert c.answers[-1] == 2 * PERIOD  # the planner's still to come
    assert c.tick(51 * MS) == ['swivel_command']
    c.state(4 * PERIOD)
    assert c.answers[-1] == 3 * PERIOD  # the driver's answer to 3 still to come
    assert c.tick(102 * MS) == ['cmd_vel']


def test_a_released_or_refused_swivel_command_is_not_waited_for():
    c = planner_chained()
    c.state(3 * PERIOD)
    c.swivel_command(2 * PERIOD, hold=False)  # released: the pending state goes at once
    assert c.answers[-1] == 3 * PERIOD
    c.state(4 * PERIOD)
    assert c.answers[-1] == 4 * PERIOD
    # Refused, a stamped command answers its cycle but changes nothing else: not chained.
    c.swivel_command(0, hold=True)  # held by hand (unstamped): held, not chained
    c.swivel_command(4 * PERIOD, applied=False)
    assert c.chain.planner.heard_ns == 4 * PERIOD
    c.state(5 * PERIOD)
    c.state(6 * PERIOD)
    assert c.answers[-1] == 6 * PERIOD


def test_lockstep_off_never_waits():
    c = planner_chained(swivel_command=False, cmd_vel=False)
    c.cmd_vel(2 * PERIOD)
    c.state(3 * PERIOD)
    assert c.answers == [PERIOD, 2 * PERIOD, 3 * PERIOD]


def test_a_sim_reset_forgets_the_old_worlds_state_and_commands():
    c = planner_chained()
    c.state(3 * PERIOD)  # pending
    c.chain.forget(4 * PERIOD)
    assert c.chain.planner.heard_ns == 0 and not c.chain.planner.chained
    assert c.tick(10_000 * MS) == [] and c.answers[-1] == 2 * PERIOD  # dropped
    c.state(4 * PERIOD)  # the new world: nothing chained
    assert c.answers[-1] == 4 * PERIOD
    c.state(5 * PERIOD)
    c.swivel_command(4 * PERIOD)
    c.state(6 * PERIOD)
    c.chain.forget(6 * PERIOD)  # a pending state at the reset's stamp is kept
    assert c.chain.tick(c.holding, 10_000 * MS) == (6 * PERIOD, [])


def test_a_restarted_sim_forgets_the_old_worlds_commands():
    c = planner_chained()
    c.cmd_vel(2 * PERIOD)  # the driver answers the state of 2 as well
    c.state(3 * PERIOD)
    c.swivel_command(3 * PERIOD, hold=False)  # released: only the driver is waited for
    assert c.answers[-1] == 3 * PERIOD and c.chain.driver.heard_ns == 2 * PERIOD
    c.state(1 * PERIOD)  # a new sim, its clock from 0 again: answered, nothing awaited
    assert c.answers[-1] == PERIOD
    assert c.chain.driver.heard_ns == 0 and not c.chain.driver.chained
    assert c.chain.planner.heard_ns == 0 and not c.chain.planner.chained
    # Past the old world's stamps, nothing old is waited for.
    for k in range(2, 5):
        c.state(k * PERIOD)
    assert c.answers[-3:] == [2 * PERIOD, 3 * PERIOD, 4 * PERIOD]


def test_the_last_stamped_command_is_kept_in_the_callers_form_until_a_reset():
    chain = ChainedAnswers(50 * MS, True, True)
    stamp = Time(sec=1, nanosec=10)
    chain.heard(chain.planner, stamp_ns(stamp), True, True, stamp)
    chain.heard(chain.planner, 0, True, True, Time())  # unstamped: not a stamp heard
    assert chain.planner.heard_stamp is stamp and chain.planner.heard_ns == 1_000_000_010
    chain.forget(2 * PERIOD)
    assert chain.planner.heard_stamp is None and chain.planner.heard_ns == 0


def test_a_source_acts_on_the_state_after_its_first_command_when_heard_at_once():
    entry = ChainEntry()
    assert entry.state(1 * PERIOD, 0) is Entry.FIRST
    assert entry.state(2 * PERIOD, 1 * PERIOD) is Entry.ENGAGED and entry.engaged
    assert entry.state(3 * PERIOD, 2 * PERIOD) is Entry.ON


def test_a_source_repeats_its_first_command_until_the_controller_reports_it():
    entry = ChainEntry()
    assert entry.state(1 * PERIOD, 0) is Entry.FIRST
    assert entry.state(2 * PERIOD, 0) is Entry.REPEAT  # the sim ran ahead: not yet heard
    assert entry.state(5 * PERIOD, 0) is Entry.REPEAT and not entry.engaged
    assert entry.state(6 * PERIOD, 5 * PERIOD) is Entry.ENGAGED_LATE
    assert entry.state(7 * PERIOD, 0) is Entry.ON  # engaged: what it reports no longer matters


def test_an_entry_works_in_seconds_with_minus_infinity_for_none_heard():
    entry = ChainEntry()
    assert entry.state(0.01, -math.inf) is Entry.FIRST
    assert entry.state(0.02, -math.inf) is Entry.REPEAT
    assert entry.state(0.03, 0.02) is Entry.ENGAGED_LATE
