"""CommandPace: a free-running sim never steps with a command older than its bound (fake clock)."""

import pytest

from swivel_car_sim.command_pace import CommandPace

MS = 1_000_000  # [ns]
PERIOD = 10 * MS  # [ns] control period


def test_without_a_stamped_command_the_sim_runs_free():
    pace = CommandPace(PERIOD, 1000 * MS, now_ns=0)
    assert all(pace.may_step(k * PERIOD, now_ns=0) for k in range(1000))


@pytest.mark.parametrize('max_age_periods', [0, 1, 3])
def test_the_sim_steps_on_only_within_max_age_of_the_newest_command(max_age_periods):
    pace = CommandPace(max_age_periods * PERIOD, 1000 * MS, now_ns=0)
    pace.heard(50 * PERIOD, now_ns=0)
    for k in range(50 + max_age_periods + 1):
        assert pace.may_step(k * PERIOD, now_ns=0)
    assert not pace.may_step((51 + max_age_periods) * PERIOD, now_ns=999 * MS)
    pace.heard(51 * PERIOD, now_ns=999 * MS)  # the next answer lets it go one period on
    assert pace.may_step((51 + max_age_periods) * PERIOD, now_ns=999 * MS)
    assert not pace.may_step((52 + max_age_periods) * PERIOD, now_ns=999 * MS)
    assert not pace.timed_out


def test_an_older_command_does_not_move_the_newest_back():
    pace = CommandPace(PERIOD, 0, now_ns=0)
    pace.heard(20 * PERIOD, now_ns=0)
    pace.heard(5 * PERIOD, now_ns=0)  # a late one, out of order
    assert pace.newest_ns == 20 * PERIOD
    assert pace.may_step(21 * PERIOD, now_ns=0)


def test_after_the_timeout_the_sim_runs_free_until_a_command_comes():
    pace = CommandPace(PERIOD, 100 * MS, now_ns=0)
    pace.heard(10 * PERIOD, now_ns=0)
    assert not pace.may_step(12 * PERIOD, now_ns=100 * MS)  # the timeout itself still waits
    assert pace.may_step(12 * PERIOD, now_ns=100 * MS + 1)
    assert pace.timed_out
    assert pace.may_step(500 * PERIOD, now_ns=100 * MS + 2)  # free, the watchdog stops the car
    # The controller is back, catching up: the sim waits again until it has.
    pace.heard(13 * PERIOD, now_ns=200 * MS)
    assert not pace.timed_out
    assert not pace.may_step(500 * PERIOD, now_ns=250 * MS)
    pace.heard(499 * PERIOD, now_ns=260 * MS)
    assert pace.may_step(500 * PERIOD, now_ns=260 * MS)


def test_timeout_zero_waits_forever():
    pace = CommandPace(0, 0, now_ns=0)
    pace.heard(PERIOD, now_ns=0)
    assert not pace.may_step(2 * PERIOD, now_ns=10 ** 15)


def test_a_restart_counts_the_wait_afresh():
    pace = CommandPace(0, 100 * MS, now_ns=0)
    pace.heard(PERIOD, now_ns=0)
    pace.restart(now_ns=10_000 * MS)  # resumed after a long pause
    assert not pace.may_step(2 * PERIOD, now_ns=10_050 * MS)
    assert pace.may_step(2 * PERIOD, now_ns=10_101 * MS)


def test_stale_is_older_than_max_age():
    pace = CommandPace(2 * PERIOD, 0, now_ns=0)
    assert not pace.stale(8 * PERIOD, 10 * PERIOD)
    assert pace.stale(8 * PERIOD - 1, 10 * PERIOD)
    assert not pace.stale(11 * PERIOD, 10 * PERIOD)  # ahead of the sim (another clock)


@pytest.mark.parametrize('max_age,timeout', [(-1, 0), (0, -1)])
def test_negative_bounds_are_refused(max_age, timeout):
    with pytest.raises(ValueError, match='must be >= 0'):
        CommandPace(max_age, timeout, now_ns=0)
