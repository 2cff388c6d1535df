"""The sim's hardware clock (swivel_car_sim.wall_clock) on a fake system clock."""

from swivel_car_sim.wall_clock import MAX_LAG_NS, QUIET_LAG_NS, WallPacer

PERIOD = 10_000_000  # [ns]
START = 1_700_000_000_000_000_000  # [ns] a system clock reading


def test_stamps_follow_the_physics_from_the_system_clock_at_start():
    pacer = WallPacer(PERIOD, 0, START)
    assert pacer.stamp_ns(0) == START
    assert pacer.stamp_ns(3 * PERIOD) - pacer.stamp_ns(2 * PERIOD) == PERIOD


def test_a_late_timer_catches_up_the_periods_due():
    pacer = WallPacer(PERIOD, 0, START)
    assert pacer.due(0, START + PERIOD // 2) == (0, 0)
    assert pacer.due(0, START + PERIOD) == (0, 1)
    assert pacer.due(0, START + 3 * PERIOD + 1) == (0, 3)  # a timer 25 ms late: three at once
    assert pacer.due(3 * PERIOD, START + 3 * PERIOD + 1) == (0, 0)
    assert pacer.skipped_ns == 0


def test_a_busy_machine_steps_the_backlog_publishing_only_its_last_state():
    pacer = WallPacer(PERIOD, 0, START)
    late = START + QUIET_LAG_NS + 2 * PERIOD + 1  # [ns]
    quiet, published = pacer.due(0, late)
    assert (quiet, published) == ((QUIET_LAG_NS + 2 * PERIOD) // PERIOD - 1, 1)
    assert pacer.skipped_ns == 0  # the physics goes on: the stamps stay the physics' own
    assert pacer.stamp_ns((quiet + published) * PERIOD) <= late


def test_a_stall_beyond_the_lag_limit_is_skipped_and_stamps_jump_ahead():
    pacer = WallPacer(PERIOD, 0, START)
    stalled = START + MAX_LAG_NS + 50 * PERIOD
    assert pacer.due(0, stalled) == (0, 1)
    assert pacer.skipped_ns == MAX_LAG_NS + 49 * PERIOD
    assert pacer.stamp_ns(PERIOD) == stalled  # the next state: sampled now
    assert pacer.due(PERIOD, stalled) == (0, 0)


def test_a_restart_after_a_pause_moves_the_stamps_forward_never_back():
    pacer = WallPacer(PERIOD, 0, START)
    pacer.restart(PERIOD, START + 5 * PERIOD)  # resumed 4 periods after its last state's time
    assert pacer.stamp_ns(PERIOD) == START + 5 * PERIOD
    pacer.restart(10 * PERIOD, START + 6 * PERIOD)  # stepped ahead while paused
    assert pacer.stamp_ns(10 * PERIOD) == START + 14 * PERIOD
