"""
The planner's inputs, refused where they enter, and the attitude it trusts.

A non-finite field is refused where it enters, said rate-limited; the roll and pitch the
planner trusts follow the gyro through the jolts that throw a fused orientation off.
"""

import math

import pytest
from swivel_car_planner.core import inputs

QUATERNION = (0.0, 0.0, 0.0, 1.0)
ODOM = {'pose.pose.position.x': 0, 'pose.pose.position.y': 1,
        **{f'pose.pose.orientation.{axis}': (2, i) for i, axis in enumerate('xyzw')},
        'twist.twist.linear.x': 3}
# Attitude.update's arguments: stamp, orientation, angular velocity
IMU = {**{f'orientation.{axis}': (1, i) for i, axis in enumerate('xyzw')},
       **{f'angular_velocity.{axis}': (2, i) for i, axis in enumerate('xyz')}}
# controller_state_values' arguments: set point, torque, command stamp, swivel, swivel rate
CONTROLLER_STATE = {'set_point': 0, 'torque': 1, 'measured': 3, 'measured_rate': 4}


def _with(arguments, where, value):
    """Return ``arguments`` with the one at ``where`` (index, or index in a tuple) replaced."""
    arguments = list(arguments)
    if isinstance(where, tuple):
        index, item = where
        numbers = list(arguments[index])
        numbers[item] = value
        arguments[index] = tuple(numbers)
    else:
        arguments[where] = value
    return arguments


CASES = ([(inputs.odom_values, (1.0, 2.0, QUATERNION, 0.3), name, where)
          for name, where in ODOM.items()]
         + [(inputs.Attitude(10.0).update, (0.0, QUATERNION, (0.0, 0.0, 0.0)), name, where)
            for name, where in IMU.items()]
         + [(inputs.controller_state_values, (0.1, 2.0, -math.inf, 0.1, 0.0), name, where)
            for name, where in CONTROLLER_STATE.items()])


@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize('values, arguments, name, where', CASES)
def test_a_non_finite_field_is_refused_by_name(values, arguments, name, where, bad):
    values(*arguments)  # finite: taken
    with pytest.raises(ValueError, match=rf'^{name} must be a finite number, got {bad}$'):
        values(*_with(arguments, where, bad))


def test_no_controller_command_heard_yet_is_no_bad_input():
    assert inputs.controller_state_values(0.1, 2.0, -math.inf, 0.1, 0.0)[2] == -math.inf


def test_refusals_are_said_once_per_interval_per_topic_with_how_many_were_held_back():
    log = inputs.RefusalLog(5.0)
    assert log.line('odom', 'x is nan', 10.0) == 'odom refused: x is nan: not acted on'
    assert log.line('odom', 'x is nan', 12.0) is None
    assert log.line('imu', 'y is inf', 12.0) == 'imu refused: y is inf: not acted on'
    assert log.line('odom', 'x is nan', 14.99) is None
    assert log.line('odom', 'x is nan', 15.0) == (
        'odom refused: x is nan: not acted on (2 more refused since the last line)')
    assert log.line('odom', 'x is nan', 20.0) == 'odom refused: x is nan: not acted on'


# --- the attitude the planner trusts -----------------------------------------------------

PERIOD = 0.01  # [s] the sim's IMU, 100 Hz
TAU = 10.0  # [s] PlannerConfig.attitude_time_constant's default
BOARD_TAU = 1.0  # [s] the realistic board's Mahony filter: fusion_gain 1/s


def _quaternion_of(roll, pitch, yaw):
    """(x, y, z, w) of REP-103 fixed-axis roll, pitch, yaw [rad]."""
    cr, sr = math.cos(roll / 2.0), math.sin(roll / 2.0)
    cp, sp = math.cos(pitch / 2.0), math.sin(pitch / 2.0)
    cy, sy = math.cos(yaw / 2.0), math.sin(yaw / 2.0)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def _climb_pitch(t):
    """
    Return a 2 cm climb's pitch [rad] at ``t`` [s] and its rate [rad/s].

    Level, nose up 0.05 rad (the front on top: asin(0.02 / 0.4)) over 1-2 s, held, level
    again over 5-6 s (the rear up); cosine ramps, so the rate is smooth.
    """
    def ramp(start):
        s = min(1.0, max(0.0, t - start))
        return 0.5 * (1.0 - math.cos(math.pi * s)), (
            0.5 * math.pi * math.sin(math.pi * s) if 0.0 < t - start < 1.0 else 0.0)
    (up, up_rate), (down, down_rate) = ramp(1.0), ramp(5.0)
    return -0.05 * (up - down), -0.05 * (up_rate - down_rate)


def _run(samples, time_constant=TAU):
    attitude = inputs.Attitude(time_constant)
    return [attitude.update(t, orientation, rate) for t, orientation, rate in samples]


def _jolted_climb(jolt_roll=0.0):
    """
    Return samples of a 2 cm climb whose fused angles a jolt throws off; the gyro is right.

    The jolt at 6 s (the rear wheels leaving the riser) tilts the fused pitch by 0.04 rad
    (and the roll by ``jolt_roll``), which the board's filter takes back with its own time
    constant: 0.03-0.05 rad is what the realistic board showed after a climb's jolts.
    Returns [(stamp, fused quaternion, body rates)] and the true (roll, pitch) per sample.
    """
    samples, truth = [], []
    for k in range(int(10.0 / PERIOD) + 1):
        t = k * PERIOD
        pitch, pitch_rate = _climb_pitch(t)
        fade = math.exp(-(t - 6.0) / BOARD_TAU) if t >= 6.0 else 0.0
        samples.append((t, _quaternion_of(jolt_roll * fade, pitch + 0.04 * fade, 0.3),
                        (0.0, pitch_rate, 0.0)))
        truth.append((0.0, pitch))
    return samples, truth


def test_a_jolt_that_throws_the_fused_pitch_off_barely_moves_the_pitch_the_planner_trusts():
    samples, truth = _jolted_climb()
    pitch = [angles[1] for angles in _run(samples)]
    fused = [inputs.roll_pitch(*orientation)[1] for _, orientation, _ in samples]
    assert max(abs(f - p) for f, (_, p) in zip(fused, truth)) > 0.039  # as the board reads
    # The filter low-passes the fused error E exp(-t / board tau) at TAU: its response is at
    # most the error's integral over TAU, E board tau / TAU = 0.004 rad; the trapezoid on the
    # sampled rates adds < 1e-4 rad (dt^2 / 12 times the rate's largest change, per second).
    # The planner tells a car on top of a 2 cm step from one with only its front up by
    # 0.025 rad: the fused pitch (0.04 off) misjudges it, this does not.
    bound = 0.04 * BOARD_TAU / TAU + 1e-4
    errors = [abs(p - true) for p, (_, true) in zip(pitch, truth)]
    assert max(errors) < bound, max(errors)
    assert max(errors) > 0.5 * bound  # the fused pitch still pulls: the filter is not the gyro


def test_a_jolt_that_throws_the_fused_roll_off_barely_moves_the_roll():
    samples, _ = _jolted_climb(jolt_roll=0.04)
    rolls = [angles[0] for angles in _run(samples)]
    assert max(abs(roll) for roll in rolls) < 0.04 * BOARD_TAU / TAU + 1e-4  # as the pitch


def test_with_exact_fused_angles_and_gyro_the_angles_are_exact():
    # The ideal sensors: every figure of the truth, to the trapezoid's error (above).
    samples, truth = [], []
    for k in range(int(8.0 / PERIOD) + 1):
        t = k * PERIOD
        pitch, pitch_rate = _climb_pitch(t)
        roll, roll_rate = 0.5 * pitch, 0.5 * pitch_rate
        # Body rates of roll' and pitch' at yaw 0.7: p = roll' - sin(pitch) yaw' (yaw' = 0),
        # q = cos(roll) pitch', r = -sin(roll) pitch'.
        samples.append((t, _quaternion_of(roll, pitch, 0.7),
                        (roll_rate, math.cos(roll) * pitch_rate, -math.sin(roll) * pitch_rate)))
        truth.append((roll, pitch))
    for (roll, pitch, yaw), (true_roll, true_pitch) in zip(_run(samples), truth):
        assert roll == pytest.approx(true_roll, abs=1e-4)
        assert pitch == pytest.approx(true_pitch, abs=1e-4)
        assert yaw == pytest.approx(0.7, abs=1e-12)  # the fused yaw as it comes


def test_a_gyro_bias_costs_at_most_the_bias_times_the_time_constant():
    # Level and still, the fused angles right, the gyro 0.001 rad/s off in pitch (five times
    # the realistic BMI088's residual after its calibration at rest): the filter settles where
    # the pull cancels the bias, bias * TAU = 0.01 rad, never beyond.
    bias = 0.001  # [rad/s]
    samples = [(k * PERIOD, QUATERNION, (0.0, bias, 0.0)) for k in range(int(60.0 / PERIOD))]
    pitches = [angles[1] for angles in _run(samples)]
    assert max(pitches) <= bias * TAU
    assert pitches[-1] == pytest.approx(bias * TAU * (1.0 - math.exp(-60.0 / TAU)), rel=1e-2)


def test_it_starts_at_the_fused_angles_and_again_after_a_gap_or_a_reset():
    fused = _quaternion_of(0.02, -0.05, 1.0)
    spin = (0.0, 0.5, 0.0)  # [rad/s] a gyro that would move the pitch if integrated
    attitude = inputs.Attitude(TAU)
    roll, pitch, yaw = attitude.update(5.0, fused, spin)  # the first sample
    assert (roll, pitch, yaw) == pytest.approx((0.02, -0.05, 1.0), abs=1e-12)
    assert attitude.update(5.0, QUATERNION, spin) == (roll, pitch, yaw)  # its stamp again
    moved = attitude.update(5.0 + PERIOD, fused, spin)[1]
    assert moved == pytest.approx(-0.05 + 0.5 * PERIOD, abs=1e-4)
    gap = 5.0 + PERIOD + inputs.Attitude.MAX_GAP + PERIOD  # the rate between is unknown
    assert attitude.update(gap, fused, spin)[1] == pytest.approx(-0.05, abs=1e-12)
    assert attitude.update(1.0, QUATERNION, spin)[1] == 0.0  # time went back: a sim reset


@pytest.mark.parametrize('bad', [0.0, -1.0, math.nan, math.inf])
def test_a_time_constant_not_above_zero_is_refused(bad):
    with pytest.raises(ValueError, match='time_constant must be'):
        inputs.Attitude(bad)


def test_a_refused_sample_changes_nothing():
    attitude = inputs.Attitude(TAU)
    attitude.update(0.0, QUATERNION, (0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match='angular_velocity.y'):
        attitude.update(PERIOD, QUATERNION, (0.0, math.nan, 0.0))
    assert attitude.update(2 * PERIOD, QUATERNION, (0.0, 0.0, 0.0)) == (0.0, 0.0, 0.0)
