"""Tests of the offset-tricycle planar model and its odometry integrator."""

import math

from hypothesis import given, settings, strategies as st
import numpy as np
import pytest

from swivel_car_model import kinematics, planar
from swivel_car_model.params import SwivelCarParams

P = SwivelCarParams()
MODEL = planar.tabulated_model(P)
LIMIT = 1.4  # [rad] a swivel range well clear of the singular pi/2

angles = st.floats(-LIMIT, LIMIT, allow_nan=False)
rates = st.floats(-3.0, 3.0, allow_nan=False)


@given(v=st.floats(-2.0, 2.0), a=st.floats(0.1, 1.0), delta=st.floats(-1.2, 1.2))
def test_without_offset_it_is_the_plain_tricycle(v, a, delta):
    omega = planar.offset_tricycle_yaw_rate(v, a, 0.0, 0.0, 0.0, delta)
    assert omega == pytest.approx(v * math.tan(delta) / a, rel=1e-9, abs=1e-12)


def test_yaw_rate_rejects_the_singular_and_non_finite():
    with pytest.raises(ValueError, match='not determined'):
        planar.offset_tricycle_yaw_rate(1.0, 0.0, 0.0, 0.0, 0.0, 0.3)
    with pytest.raises(ValueError, match='finite'):
        planar.offset_tricycle_yaw_rate(math.nan, 0.4, 0.0, 0.0, 0.0, 0.3)


def test_straight_at_zero_swivel():
    v, omega = planar.body_twist(P, 0.0, 0.0, 2.0)
    assert v == pytest.approx(2.0 * P.r)
    assert omega == 0.0


def test_positive_swivel_turns_right_for_positive_phi():
    assert planar.curvature_for_swivel(P, 0.5) < 0.0
    assert planar.curvature_for_swivel(P, -0.5) == pytest.approx(
        -planar.curvature_for_swivel(P, 0.5))
    flipped = SwivelCarParams(phi=-math.pi / 3)
    assert planar.curvature_for_swivel(flipped, 0.5) > 0.0


def test_curvature_grows_monotonically_with_the_swivel():
    curvature = [abs(planar.curvature_for_swivel(P, t)) for t in np.linspace(0.0, 1.56, 300)]
    assert np.all(np.diff(curvature) > 0.0)


@given(theta2=angles)
def test_swivel_for_curvature_inverts_curvature_for_swivel(theta2):
    curvature = planar.curvature_for_swivel(P, theta2)
    assert planar.swivel_for_curvature(P, curvature, LIMIT) == pytest.approx(theta2, abs=1e-8)


def test_swivel_for_curvature_rejects_bad_input():
    reachable = planar.max_curvature(P, LIMIT)
    with pytest.raises(ValueError, match='beyond'):
        planar.swivel_for_curvature(P, 1.01 * reachable, LIMIT)
    with pytest.raises(ValueError, match='finite'):
        planar.swivel_for_curvature(P, math.inf)
    with pytest.raises(ValueError):
        planar.swivel_for_curvature(P, 1.0, swivel_limit=2.0)
    assert planar.swivel_for_curvature(P, 0.0) == 0.0


def test_body_twist_rejects_bad_input():
    for args in ((math.nan, 0.0, 1.0), (0.1, math.inf, 1.0), (0.1, 0.0, -math.inf),
                 (P.max_swivel_angle + 0.01, 0.0, 1.0)):
        with pytest.raises(ValueError):
            planar.body_twist(P, *args)


def test_swivel_sweep_without_rolling_does_not_move_base_link():
    # The rear wheels stand still on the ground; their joints see the body pitch back.
    theta2, rate = 0.6, 0.4
    joint_rate = kinematics.lift_angle_derivative(P, theta2) * rate
    v, _ = planar.body_twist(P, theta2, rate, joint_rate)
    assert v == pytest.approx(0.0, abs=1e-9)


def _drive(odometry, swivel_of_t, wheel_rate_of_t, duration, dt):
    """Feed the odometry a trajectory; return the world positions of the contact point."""
    poses, swivels = [], []
    for k in range(int(round(duration / dt)) + 1):
        t = k * dt
        theta2 = swivel_of_t(t)
        rate = (swivel_of_t(t + 1e-6) - swivel_of_t(t - 1e-6)) / 2e-6
        odometry.update(theta2, rate, wheel_rate_of_t(t), dt if k else 0.0)
        poses.append((odometry.x, odometry.y, odometry.yaw))
        swivels.append(theta2)
    x, y, yaw = np.array(poses).T
    swivels = np.array(swivels)
    a, b = kinematics.contact_point(P, swivels)  # exact, vectorised: the reference
    c, s = np.cos(yaw), np.sin(yaw)
    contacts = np.stack([x + c * a - s * b, y + s * a + c * b], axis=1)
    return contacts, yaw + kinematics.steering_angle(P, swivels), swivels >= 0.0


def test_steering_wheel_never_skids_while_the_swivel_moves():
    """
    Check the steering wheel's contact point moves only along its rolling direction.

    The pose integrated from body_twist keeps the constraint the model is built on, also
    while the swivel turns and changes sides through zero.
    """
    odometry = planar.OffsetTricycleOdometry(P)
    dt = 1e-3
    contacts, headings, sides = _drive(odometry, lambda t: 1.2 * math.sin(0.8 * t),
                                       lambda t: 4.0 + 2.0 * math.cos(t), 6.0, dt)
    velocity = np.gradient(contacts, dt, axis=0)
    lateral = -velocity[:, 0] * np.sin(headings) + velocity[:, 1] * np.cos(headings)
    # Where the contact passes to the other front wheel the difference quotient is no velocity.
    same_wheel = (sides[:-2] == sides[1:-1]) & (sides[1:-1] == sides[2:])
    assert np.count_nonzero(~same_wheel) <= 8
    lateral = lateral[1:-1][same_wheel]
    speed = np.linalg.norm(velocity[1:-1][same_wheel], axis=1)
    assert np.max(np.abs(lateral)) < 1e-4 * np.max(speed)


@pytest.mark.parametrize('theta2', [0.2, -0.7, 1.3])
def test_constant_swivel_drives_a_closed_circle(theta2):
    odometry = planar.OffsetTricycleOdometry(P)
    wheel_rate = 3.0  # [rad/s]
    # The circle of the odometry's own (tabulated) twist: this checks the integration.
    v, omega = MODEL.body_twist(theta2, 0.0, wheel_rate)
    period = 2.0 * math.pi / abs(omega)
    steps = 1000
    positions = []
    for k in range(steps + 1):
        odometry.update(theta2, 0.0, wheel_rate, period / steps if k else 0.0)
        positions.append((odometry.x, odometry.y))
    positions = np.array(positions)
    radius = 1.0 / MODEL.curvature(theta2)
    # Centre of rotation on the rear axle line at y = 1 / curvature.
    assert np.allclose(np.hypot(positions[:, 0], positions[:, 1] - radius), abs(radius),
                       atol=1e-9)
    assert positions[-1] == pytest.approx([0.0, 0.0], abs=1e-9)
    assert abs(odometry.yaw) < 1e-9


def test_arc_step_matches_fine_integration():
    v, omega, yaw, dt = 0.7, 1.3, 2.9, 0.4
    dx, dy, dyaw = planar.arc_step(v, omega, yaw, dt)
    n = 20000
    x = y = 0.0
    heading = yaw
    for _ in range(n):
        x += v * math.cos(heading + 0.5 * omega * dt / n) * dt / n
        y += v * math.sin(heading + 0.5 * omega * dt / n) * dt / n
        heading += omega * dt / n
    assert (dx, dy, dyaw) == pytest.approx((x, y, omega * dt), abs=1e-9)
    assert planar.arc_step(0.5, 0.0, 0.3, 2.0) == pytest.approx(
        (math.cos(0.3), math.sin(0.3), 0.0))


def test_odometry_reset_set_pose_and_wrap():
    odometry = planar.OffsetTricycleOdometry(P)
    odometry.set_pose(1.0, -2.0, 3.0 * math.pi)
    assert (odometry.x, odometry.y, odometry.yaw) == pytest.approx((1.0, -2.0, math.pi))
    odometry.update(-0.8, 0.0, 5.0, 0.0)
    for _ in range(300):
        odometry.update(-0.8, 0.0, 5.0, 0.01)
        assert -math.pi < odometry.yaw <= math.pi
    odometry.reset()
    assert (odometry.x, odometry.y, odometry.yaw, odometry.v) == (0.0, 0.0, 0.0, 0.0)


@settings(max_examples=30)
@given(bad=st.sampled_from([math.nan, math.inf, -math.inf]),
       slot=st.integers(0, 3))
def test_odometry_bad_input_changes_nothing(bad, slot):
    odometry = planar.OffsetTricycleOdometry(P)
    odometry.update(0.3, 0.0, 2.0, 0.0)
    odometry.update(0.3, 0.0, 2.0, 0.1)
    before = (odometry.x, odometry.y, odometry.yaw, odometry.v, odometry.omega)
    args = [0.3, 0.0, 2.0, 0.1]
    args[slot] = bad
    with pytest.raises(ValueError):
        odometry.update(*args)
    with pytest.raises(ValueError):
        odometry.update(0.3, 0.0, 2.0, -0.01)
    with pytest.raises(ValueError):
        odometry.set_pose(bad, 0.0, 0.0)
    assert (odometry.x, odometry.y, odometry.yaw, odometry.v, odometry.omega) == before


@pytest.mark.parametrize('theta2', [-1e-7, -1e-12, 0.0, 1e-12, 1e-7])
def test_twist_is_smooth_through_zero_swivel(theta2):
    """Near zero the contact changes wheel; the twist must not see that jump as motion."""
    v, omega = planar.body_twist(P, theta2, 0.01, 5.0)
    # The swivel's 0.01 rad/s moves the contact along x by 6e-4 of v here (the sign
    # follows the contact's side: exact, not rounding), omega -1.5e-3 rad/s; the contact's
    # change of wheel taken for motion would be orders of magnitude more.
    assert v == pytest.approx(5.0 * P.r, rel=1e-3)
    assert abs(omega) < 0.01


def test_yaw_rate_from_the_rear_axle():
    odometry = planar.OffsetTricycleOdometry(P)
    v, omega = odometry.update(0.5, 0.0, 4.0, 0.0, rear_wheel_rate_difference=2.0)
    assert v == pytest.approx(planar.body_twist(P, 0.5, 0.0, 4.0)[0])
    assert omega == pytest.approx(P.r * 2.0 / (2.0 * P.h))
    with pytest.raises(ValueError):
        odometry.update(0.5, 0.0, 4.0, 0.01, rear_wheel_rate_difference=math.nan)


def test_wheel_rate_for_speed():
    assert planar.wheel_rate_for_speed(P, 0.3) == pytest.approx(0.3 / P.r)
    with pytest.raises(ValueError):
        planar.wheel_rate_for_speed(P, math.nan)


# --- the tabulated model against the exact one ----------------------------------------------
# The bounds TabulatedModel's docstring states; the odometry's own error on the benchmark
# routes is 0.04-0.7 % of the distance, so a few 1e-6 relative in the twist is far below it.

def test_tabulated_geometry_is_the_exact_geometry_over_the_whole_swivel_range():
    # 4000 angles, none on a table sample but the last: the worst case lies between samples.
    # (0 and -0.0 are the positive side's, as in the exact model: the twist test has them.)
    u = np.linspace(0.0, P.max_swivel_angle, 4001)[1:]
    exact = np.array(planar._geometry_arrays(P, u))
    lift = np.asarray(kinematics.lift_angle(P, u))
    for sign in (1.0, -1.0):
        tabulated = np.array([MODEL.geometry(sign * x) for x in u]).T
        mirrored = exact * np.array([1.0, sign, sign, sign, 1.0, sign])[:, None]
        error = np.max(np.abs(tabulated - mirrored), axis=1)
        assert np.all(error[:2] < 1e-8)  # contact point [m]
        assert error[2] < 1e-7  # steering angle [rad]
        assert np.all(error[3:] < 1e-6)  # derivatives [m/rad], [1]
        tabulated_lift = np.array([MODEL.lift_angle(sign * x) for x in u])
        assert np.max(np.abs(tabulated_lift - lift)) < 1e-8  # [rad]


@pytest.mark.parametrize('p', [P, SwivelCarParams(phi=-math.pi / 3, h=0.1, r=0.05)])
def test_tabulated_twist_and_curvature_match_the_exact_ones(p):
    model = planar.tabulated_model(p)
    rng = np.random.default_rng(3)
    for theta2 in np.append(np.linspace(-1.55, 1.55, 32), [0.0, 1e-7, -1e-7]):
        rate, wheel_rate = rng.uniform(-2.0, 2.0), rng.uniform(-8.0, 8.0)
        v, omega = planar.body_twist(p, theta2, rate, wheel_rate)
        scale = abs(v) + abs(omega)
        # Over 12,000 angles (uniform and random, 0.01 rad around 0 included) with random
        # rates, on this test's geometries and phi -pi/3 with the default h and r, the linear
        # table's twist is within 2.7e-6 of |v| + |omega| (a
        # component near zero is off by more than 1e-6 of itself), its curvature within
        # 4.4e-6 relative where |curvature| > 1e-3 1/m and 5.4e-9 1/m below; about x4 margin.
        # Still 20 times below the odometry's own error on the benchmark routes.
        assert model.body_twist(theta2, rate, wheel_rate) == pytest.approx(
            (v, omega), abs=1e-5 * scale)
        assert model.curvature(theta2) == pytest.approx(planar.curvature_for_swivel(p, theta2),
                                                        rel=2e-5, abs=5e-8)


@pytest.mark.parametrize('p', [P, SwivelCarParams(phi=-math.pi / 3)])
def test_tabulated_swivel_for_curvature_inverts_the_exact_curvature(p):
    model = planar.tabulated_model(p)
    for theta2 in np.linspace(-LIMIT, LIMIT, 57):
        curvature = planar.curvature_for_swivel(p, theta2)
        assert model.swivel_for_curvature(curvature, LIMIT) == pytest.approx(theta2, abs=1e-7)
    assert model.swivel_for_curvature(0.0, LIMIT) == 0.0
    reachable = planar.max_curvature(p, LIMIT)
    assert abs(model.swivel_for_curvature(reachable, LIMIT)) == pytest.approx(LIMIT, abs=1e-7)
    for bad in (1.01 * reachable, 1e9, math.nan, math.inf):
        with pytest.raises(ValueError, match='beyond|finite'):
            model.swivel_for_curvature(bad, LIMIT)


def test_tabulated_model_rejects_what_the_exact_one_rejects():
    for args in ((math.nan, 0.0, 1.0), (0.1, math.inf, 1.0), (0.1, 0.0, -math.inf),
                 (P.max_swivel_angle + 0.01, 0.0, 1.0), (-math.inf, 0.0, 1.0)):
        with pytest.raises(ValueError):
            MODEL.body_twist(*args)
    with pytest.raises(ValueError, match='finite and within'):
        MODEL.lift_angle(math.nan)
    with pytest.raises(ValueError, match='not determined'):
        MODEL.curvature(math.pi / 2)
    with pytest.raises(ValueError, match='overflows'):
        MODEL.body_twist(0.3, -1.7e308, 1.7e308)
    assert planar.tabulated_model(SwivelCarParams()) is MODEL
