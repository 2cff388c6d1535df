"""
The odometry's joint_states gate (core.odometry_input) integrates no message it cannot trust.

Before (issue 12), one wheel rate of 1e300, or one stamp of 0 s while driving, put the
odometry metres to 1e296 m off for good.
"""

import math

from hypothesis import given, settings, strategies as st
import pytest

from swivel_car_control.core.joint_states import JointStateOdometry, MAX_SWIVEL_RATE
from swivel_car_control.core.odometry_input import (
    GatedOdometry, JointStateGate, MAX_GAP, Verdict, WHEEL_RATE_FACTOR)
from swivel_car_model.description import CarDescription

ROBOT = CarDescription()
NAMES = ['swivel_joint', 'rear_left_wheel_joint', 'rear_right_wheel_joint']
WHEEL_LIMIT = WHEEL_RATE_FACTOR * ROBOT.drive_speed_limit  # [rad/s]
LIMITS = {'swivel_joint': MAX_SWIVEL_RATE, 'rear_left_wheel_joint': WHEEL_LIMIT,
          'rear_right_wheel_joint': WHEEL_LIMIT}
PERIOD = 0.01  # [s]


def gate() -> JointStateGate:
    return JointStateGate(LIMITS)


def verdicts(g: JointStateGate, stamps) -> list[Verdict]:
    return [g.admit(t, NAMES, [0.0, 1.0, 1.0]).verdict for t in stamps]


@pytest.mark.parametrize('velocities', [
    [0.0, 1e300, 1e300], [0.0, -1e12, 0.0], [0.0, math.inf, 1.0], [-math.inf, 1.0, 1.0],
    [MAX_SWIVEL_RATE * 1.01, 0.0, 0.0], [0.0, 0.0, WHEEL_LIMIT * 1.01]])
def test_an_impossible_velocity_is_refused_naming_the_joint(velocities):
    g = gate()
    admission = g.admit(1.0, NAMES, velocities)
    assert admission.verdict is Verdict.REFUSE
    assert 'velocity' in admission.reason and 'joint' in admission.reason
    assert g.last_time is None


@pytest.mark.parametrize('velocities', [[], [0.0], [math.nan, 2.0, 2.0],
                                        [MAX_SWIVEL_RATE, -WHEEL_LIMIT, WHEEL_LIMIT]])
def test_velocities_not_reported_or_within_the_limits_pass(velocities):
    assert gate().admit(1.0, NAMES, velocities).verdict is Verdict.INTEGRATE


def test_joints_the_odometry_does_not_read_are_not_checked():
    assert gate().admit(1.0, NAMES + ['front_left_wheel_joint'],
                        [0.0, 1.0, 1.0, 1e300]).verdict is Verdict.INTEGRATE


@pytest.mark.parametrize('bad', [0.0, 1.0, 10.0 - PERIOD, 2.0**31 - 1, 10.0 + 2 * MAX_GAP])
def test_one_stamp_out_of_order_or_far_ahead_is_refused_and_the_stream_goes_on(bad):
    stamps = [10.0, 10.01, bad, 10.02, 10.03]
    assert verdicts(gate(), stamps) == [Verdict.INTEGRATE, Verdict.INTEGRATE, Verdict.REFUSE,
                                        Verdict.INTEGRATE, Verdict.INTEGRATE]


def test_a_repeated_stamp_is_dropped_quietly():
    assert verdicts(gate(), [1.0, 1.0, 1.01]) == [Verdict.INTEGRATE, Verdict.REPEAT,
                                                  Verdict.INTEGRATE]


@pytest.mark.parametrize('new_base', [0.0, 5.0, 2.0**31 - 1])
def test_a_jump_the_next_message_confirms_restarts_there(new_base):
    g = gate()
    stamps = [10.0, 10.01, new_base, new_base, new_base + PERIOD, new_base + 2 * PERIOD]
    assert verdicts(g, stamps) == [Verdict.INTEGRATE, Verdict.INTEGRATE, Verdict.REFUSE,
                                   Verdict.REFUSE, Verdict.RESTART, Verdict.INTEGRATE]
    assert g.last_time == new_base + 2 * PERIOD


def test_a_non_finite_stamp_is_refused():
    g = gate()
    verdicts(g, [1.0])
    assert g.admit(math.nan, NAMES, []).verdict is Verdict.REFUSE
    assert g.admit(math.inf, NAMES, []).verdict is Verdict.REFUSE
    assert g.last_time == 1.0


@pytest.mark.parametrize('limits, max_gap', [({'j': 0.0}, 1.0), ({'j': math.nan}, 1.0),
                                             ({'j': 1.0}, 0.0), ({'j': 1.0}, math.inf)])
def test_bad_gate_limits_are_refused(limits, max_gap):
    with pytest.raises(ValueError):
        JointStateGate(limits, max_gap)


stamps = st.floats(-1e10, 1e10, allow_nan=False) | st.sampled_from([math.nan, math.inf])


@settings(max_examples=300)
@given(st.lists(stamps, max_size=30))
def test_what_is_integrated_follows_on_in_time_or_was_confirmed(sequence):
    """
    Check what is integrated follows on in time or was confirmed.

    Whatever the stamps: an integrated message lies within max_gap after the last one
    admitted; a restart follows, within max_gap, the refused message just before it.
    """
    g = gate()
    previous, previous_verdict = None, None
    for t in sequence:
        last = g.last_time
        verdict = g.admit(t, NAMES, []).verdict
        if verdict is Verdict.INTEGRATE and last is not None:
            assert 0.0 < t - last <= MAX_GAP
        elif verdict is Verdict.RESTART:
            assert previous_verdict is Verdict.REFUSE and 0.0 < t - previous <= MAX_GAP
        elif verdict is Verdict.REPEAT:
            assert t == last
        if verdict is Verdict.REFUSE:
            assert g.last_time == last
        else:
            assert g.last_time == t
        previous, previous_verdict = t, verdict


def drive(messages) -> tuple[float, float, float]:
    gated = GatedOdometry(JointStateOdometry(ROBOT.model_params(), *NAMES, 'swivel', 100.0),
                          LIMITS)
    for t, velocities in messages:
        gated.update(t, NAMES, [0.1, 0.0, 0.0], velocities)
    pose = gated.odometry.odometry
    return pose.x, pose.y, pose.yaw


bad_velocity = st.sampled_from([1e300, -1e12, math.inf, -math.inf, 2 * WHEEL_LIMIT])
bad_stamp = (st.floats(-1e10, 10.0 - 1e-6) | st.floats(11.0 + MAX_GAP, 2.0**31)
             | st.just(math.nan))


@settings(max_examples=100)
@given(rates=st.lists(st.floats(-WHEEL_LIMIT / 2, WHEEL_LIMIT / 2), min_size=100,
                      max_size=100),
       where=st.integers(1, 99), velocity=bad_velocity, stamp=bad_stamp,
       bad_is_stamp=st.booleans())
def test_one_bad_message_in_a_drive_leaves_the_pose_as_without_it(rates, where, velocity,
                                                                  stamp, bad_is_stamp):
    clean = [(10.0 + PERIOD * k, [0.0, rate, rate]) for k, rate in enumerate(rates)]
    bad = (stamp, [0.0, 1.0, 1.0]) if bad_is_stamp else (clean[where][0] - PERIOD / 2,
                                                         [0.0, velocity, 1.0])
    assert drive(clean[:where] + [bad] + clean[where:]) == drive(clean)


def test_a_restarted_sim_goes_on_integrating_from_the_pose_it_had():
    before = [(10.0 + PERIOD * k, [0.0, 2.0, 2.0]) for k in range(101)]
    after = [(PERIOD * k, [0.0, 2.0, 2.0]) for k in range(102)]
    x, _, _ = drive(before + after)
    # 1 s before, 1 s after (the restart's first message only confirms, the next starts).
    assert x == pytest.approx(2 * 2.0 * ROBOT.model_params().r, rel=0.02)


@pytest.mark.parametrize('position,velocity', [(-1e12, 0.0), (-1e12, -1e12), (1.8, 0.0)])
def test_a_swivel_glitch_is_refused_naming_the_joint_and_leaves_the_pose_as_without_it(
        position, velocity):
    clean = [(10.0 + PERIOD * k, [0.0, 2.0, 2.0]) for k in range(50)]
    gated = GatedOdometry(JointStateOdometry(ROBOT.model_params(), *NAMES, 'swivel', 100.0),
                          LIMITS)
    for t, velocities in clean[:20]:
        gated.update(t, NAMES, [0.1, 0.0, 0.0], velocities)
    admission, due = gated.update(clean[20][0] - PERIOD / 2, NAMES, [position, 0.0, 0.0],
                                  [velocity, 2.0, 2.0])
    assert admission.verdict is Verdict.REFUSE and not due
    assert "'swivel_joint'" in admission.reason and 'glitch' in admission.reason
    for t, velocities in clean[20:]:
        gated.update(t, NAMES, [0.1, 0.0, 0.0], velocities)
    pose = gated.odometry.odometry
    assert (pose.x, pose.y, pose.yaw) == drive(clean)
