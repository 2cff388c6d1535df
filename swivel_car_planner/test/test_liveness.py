"""The climb slot and the inputs' liveness on a fake sim clock and a fake wall clock."""

from swivel_car_planner.core.liveness import ClimbSlot, InputLiveness

TOPICS = ('imu', 'odom', 'controller')
TIMEOUT = 1.0  # [s]


def describe():
    return 'stamps'


def test_one_slot_for_planning_and_climbing():
    slot = ClimbSlot()
    assert not slot.busy and slot.take()
    assert slot.busy and not slot.take()  # a second request while planned
    slot.planned(None)  # the planning failed: free again
    assert not slot.busy and slot.take()
    slot.planned('climb')
    assert slot.busy and slot.climb == 'climb' and not slot.take()
    slot.end()
    assert not slot.busy and slot.climb is None


def heard_all(liveness, sim, wall, topics=TOPICS):
    for topic in topics:
        liveness.heard(topic, sim, wall)


def test_inputs_are_missing_before_the_clock_and_when_silent_on_sim_time():
    liveness = InputLiveness(TOPICS, TIMEOUT)
    assert liveness.missing(0.0, 0.0) == list(TOPICS)
    heard_all(liveness, 5.0, 100.0)
    assert liveness.missing(5.5, 100.5) == [] and liveness.not_ready(5.5, 100.5) is None
    heard_all(liveness, 6.1, 100.6, topics=('imu', 'controller'))
    assert liveness.missing(6.1, 100.6) == ['odom']
    assert liveness.not_ready(6.1, 100.6) is None  # a request: heard 0.6 s ago, wall time
    assert liveness.not_ready(6.1, 101.1) == ('no recent message on odom: are the sim, '
                                              'controller and odometry running?')


def test_a_request_takes_inputs_queued_behind_a_clock_that_leapt_ahead():
    liveness = InputLiveness(TOPICS, TIMEOUT)
    heard_all(liveness, 5.0, 100.0)
    # A loaded planner: /clock is 1.2 s ahead of the inputs heard 0.1 s of wall time ago.
    assert liveness.missing(6.2, 100.1) == list(TOPICS)
    assert liveness.not_ready(6.2, 100.1) is None


def test_a_clock_standing_still_keeps_no_input_fresh():
    liveness = InputLiveness(TOPICS, TIMEOUT)
    heard_all(liveness, 5.0, 100.0)
    heard_all(liveness, 5.0, 101.5)  # the inputs still come, sim time stands
    assert liveness.clock_stands(101.5)
    assert liveness.missing(5.0, 101.5) == list(TOPICS)
    assert liveness.not_ready(5.0, 101.5) is None  # heard on wall time
    assert liveness.not_ready(5.0, 102.6) == (
        'no recent message on imu, odom, controller: sim time has stood at 5.00 s: is the sim '
        'running, not paused?')


def test_time_going_back_or_leaping_ends_the_climb_only_once_engaged():
    liveness = InputLiveness(TOPICS, TIMEOUT)
    liveness.climb_started(5.0, 100.0)
    assert liveness.tick(5.0, 5.0, 100.0) is None
    assert liveness.tick(9.0, 9.0, 100.1) is None  # not engaged: sim time may race
    liveness.engaged(9.0)
    assert liveness.tick(9.01, 9.01, 100.2) is None
    liveness.engaged(9.01)
    stamp, why = liveness.tick(8.0, 8.0, 100.3)
    assert stamp == 8.0 and why.startswith('time went back from 9.01 s to 8.00 s')
    stamp, why = liveness.tick(10.5, 10.5, 100.3)
    assert stamp == 9.01 and why.startswith('the inputs leapt from 9.01 s to 10.50 s')


def test_a_climb_without_ticks_ends_after_two_quiet_checks_on_either_clock():
    liveness = InputLiveness(TOPICS, TIMEOUT)
    heard_all(liveness, 5.0, 100.0)
    liveness.climb_started(5.0, 100.0)
    # Sim time runs on without a tick (odometry stopped): only once engaged.
    heard_all(liveness, 6.5, 100.5, topics=('imu', 'controller'))
    assert liveness.check(6.5, 100.5, False, describe) is None  # first quiet check
    assert liveness.check(6.5, 100.5, False, describe) is None  # not engaged, wall 0.5 s
    stamp, why = liveness.check(6.5, 100.5, True, describe)
    assert stamp == 6.5 and why == ('no complete input for 1.5 s of sim time at 6.50 s; '
                                    'missing: odom; stamps')
    # A tick resets the count; then the sim stops: sim time stands, wall time tells.
    assert liveness.tick(6.5, 6.5, 100.5) is None
    assert liveness.check(6.5, 101.6, True, describe) is None
    stamp, why = liveness.check(6.5, 101.6, True, describe)
    assert stamp == 6.5 and why.startswith(
        'no complete input for 1.1 s of wall time while sim time went from 6.50 s to 6.50 s')
