"""Kinematics closed forms against independent numerics (DH chain, brute-force rim, brentq)."""

import math

from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from swivel_car_model import kinematics as k
from swivel_car_model.params import SwivelCarParams

DEFAULT = SwivelCarParams()
GEOMETRIES = [
    DEFAULT,
    SwivelCarParams(phi=-math.pi / 3),
    SwivelCarParams(phi=math.pi / 12, h=0.1, l=0.2, r=0.05),
    SwivelCarParams(phi=5 * math.pi / 12, h=0.2, r=0.1),
    SwivelCarParams(phi=-5 * math.pi / 12, h=0.12),
]
ANGLES = np.linspace(-math.pi / 2, math.pi / 2, 41)


def rim_lowest(centre, axle, r):
    """Brute-force lowest rim point of a disc: dense sample, then a bounded 1-D refine."""
    axle = axle / np.linalg.norm(axle)
    helper = np.array([1.0, 0.0, 0.0]) if abs(axle[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(axle, helper)
    u /= np.linalg.norm(u)
    v = np.cross(axle, u)

    def point(psi):
        return centre + r * (math.cos(psi) * u + math.sin(psi) * v)

    psis = np.linspace(0.0, 2 * math.pi, 3601)
    heights = centre[2] + r * (np.cos(psis) * u[2] + np.sin(psis) * v[2])
    best = psis[int(np.argmin(heights))]
    res = minimize_scalar(lambda psi: point(psi)[2], bounds=(best - 0.01, best + 0.01),
                          method='bounded', options={'xatol': 1e-12})
    return point(res.x)


def touching_wheel(p, theta2, theta1):
    frames = k.forward_kinematics(p, theta2, theta1)
    return frames.o3 if theta2 >= 0 else frames.o3_left


def lifted_wheel(p, theta2, theta1):
    frames = k.forward_kinematics(p, theta2, theta1)
    return frames.o3_left if theta2 >= 0 else frames.o3


@pytest.mark.parametrize('p', GEOMETRIES)
def test_dh_chain_matches_thesis_eq1_mapped(p):
    theta1 = k.lift_angle(p, ANGLES)
    o3 = k.forward_kinematics(p, ANGLES).o3[:, :3, 3]
    # Thesis eq. 1 with theta1 -> -theta1 and (x_T, y_T, z_T) = (x, -z, y).
    t1, t2, cx = -theta1, ANGLES, math.cos(p.phi / 2)
    x_t = 2 * p.l * np.cos(t1) * cx - p.h * np.sin(t2) * np.sin(t1 + p.phi / 2)
    y_t = 2 * p.l * np.sin(t1) * cx + p.h * np.sin(t2) * np.cos(t1 + p.phi / 2)
    z_t = -p.h * np.cos(t2)
    np.testing.assert_allclose(o3, np.stack([x_t, z_t, -y_t], axis=-1), atol=1e-12)


def test_dh_frames_at_rest_match_params():
    frames = k.forward_kinematics(DEFAULT, 0.0)
    np.testing.assert_allclose(frames.o2[:3, 3], DEFAULT.front_axle, atol=1e-12)
    np.testing.assert_allclose(frames.o1[:3, 2], DEFAULT.swivel_axis, atol=1e-12)
    np.testing.assert_allclose(frames.o3[:3, 3], [DEFAULT.wheelbase, -DEFAULT.h, 0], atol=1e-12)
    np.testing.assert_allclose(frames.o3_left[:3, 3], [DEFAULT.wheelbase, DEFAULT.h, 0],
                               atol=1e-12)
    # o1 lies on the column line apex -> front axle
    apex_to_o1 = frames.o1[:3, 3] - DEFAULT.apex
    assert np.linalg.norm(np.cross(apex_to_o1, DEFAULT.swivel_axis)) < 1e-12


@pytest.mark.parametrize('p', GEOMETRIES)
def test_lift_root_matches_numeric_solve_of_rim_contact(p):
    for theta2 in [-1.4, -0.7, -0.05, 0.05, 0.3, 0.9, 1.5]:
        def gap(theta1):
            frames = touching_wheel(p, theta2, theta1)
            return rim_lowest(frames[:3, 3], frames[:3, 2], p.r)[2] + p.r

        numeric = brentq(gap, -0.2, 1.2, xtol=1e-13)
        assert k.lift_angle(p, theta2) == pytest.approx(numeric, abs=1e-8)


@pytest.mark.parametrize('p', GEOMETRIES)
def test_contact_and_lifted_height_match_brute_force_rim(p):
    theta1 = k.lift_angle(p, ANGLES)
    cx, cy = k.contact_point(p, ANGLES)
    height = k.lifted_wheel_lowest_height(p, ANGLES)
    for i, theta2 in enumerate(ANGLES):
        touch = touching_wheel(p, theta2, theta1[i])
        lowest = rim_lowest(touch[:3, 3], touch[:3, 2], p.r)
        assert lowest[2] == pytest.approx(-p.r, abs=1e-9)
        assert (cx[i], cy[i]) == pytest.approx((lowest[0], lowest[1]), abs=1e-7)
        lifted = lifted_wheel(p, theta2, theta1[i])
        assert height[i] == pytest.approx(
            rim_lowest(lifted[:3, 3], lifted[:3, 2], p.r)[2] + p.r, abs=1e-9)


@pytest.mark.parametrize('p', GEOMETRIES)
def test_steering_matches_projected_dh_axle(p):
    frames = k.forward_kinematics(p, ANGLES)
    axle = frames.o3[:, :3, 2]
    # rolling direction = ground projection of the shaft turned by -90 deg about z
    rolling = np.stack([axle[:, 1], -axle[:, 0]], axis=-1)
    rolling *= np.sign(rolling[:, :1] + 1e-300)
    expected = np.arctan2(rolling[:, 1], rolling[:, 0])
    np.testing.assert_allclose(k.steering_angle(p, ANGLES), expected, atol=1e-12)


@pytest.mark.parametrize('p', GEOMETRIES)
def test_lift_derivative_matches_finite_difference(p):
    t = np.array([-1.2, -0.4, 0.2, 0.8, 1.3])
    eps = 1e-6
    numeric = (k.lift_angle(p, t + eps) - k.lift_angle(p, t - eps)) / (2 * eps)
    np.testing.assert_allclose(k.lift_angle_derivative(p, t), numeric, atol=1e-7)
    assert k.lift_angle_derivative(p, 0.0) == pytest.approx(p.h / (2 * p.l), rel=1e-9)


@pytest.mark.parametrize('p', GEOMETRIES)
def test_symmetry_under_swivel_sign_flip(p):
    np.testing.assert_allclose(k.lift_angle(p, -ANGLES), k.lift_angle(p, ANGLES), atol=1e-14)
    np.testing.assert_allclose(k.steering_angle(p, -ANGLES), -k.steering_angle(p, ANGLES),
                               atol=1e-14)
    x, y = k.contact_point(p, ANGLES)
    xm, ym = k.contact_point(p, -ANGLES)
    np.testing.assert_allclose(xm, x, atol=1e-14)
    nonzero = ANGLES != 0.0  # at zero both front wheels touch; the right one is reported
    np.testing.assert_allclose(ym[nonzero], -y[nonzero], atol=1e-14)
    np.testing.assert_allclose(k.lifted_wheel_lowest_height(p, -ANGLES),
                               k.lifted_wheel_lowest_height(p, ANGLES), atol=1e-14)


@pytest.mark.parametrize('p', GEOMETRIES)
def test_zero_swivel_gives_zero_lift_and_steering(p):
    assert k.lift_angle(p, 0.0) == 0.0
    assert k.steering_angle(p, 0.0) == 0.0
    assert k.lifted_wheel_lowest_height(p, 0.0) == 0.0
    assert k.contact_point(p, 0.0) == pytest.approx((p.wheelbase, -p.h), abs=1e-15)
    assert k.swivel_for_steering(p, 0.0) == 0.0
    assert k.swivel_for_step(p, 0.0) == 0.0


def test_documented_signs():
    # phi > 0: theta2 > 0 keeps the right wheel down, lifts the left one, steers right.
    frames = k.forward_kinematics(DEFAULT, 0.5)
    assert frames.o3_left[2, 3] > frames.o3[2, 3]
    assert k.steering_angle(DEFAULT, 0.5) < 0.0
    assert k.contact_point(DEFAULT, 0.5)[1] < 0.0
    assert k.lift_angle(DEFAULT, 0.5) > 0.0
    assert k.steering_angle(SwivelCarParams(phi=-math.pi / 3), 0.5) > 0.0


def test_quarter_turn_steers_ninety_degrees():
    assert abs(k.steering_angle(DEFAULT, math.pi / 2)) == pytest.approx(math.pi / 2, abs=1e-12)


@pytest.mark.parametrize('p', GEOMETRIES)
def test_swivel_for_steering_inverts_steering(p):
    limit = k.max_steering_angle(p)
    wanted = np.linspace(-limit, limit, 57)
    theta2 = k.swivel_for_steering(p, wanted)
    np.testing.assert_allclose(k.steering_angle(p, theta2), wanted, atol=1e-11)
    for value in wanted[::7]:
        scalar = k.swivel_for_steering(p, float(value))
        assert isinstance(scalar, float)
        assert k.steering_angle(p, scalar) == pytest.approx(value, abs=1e-11)


@settings(max_examples=60)
@given(phi=st.floats(0.05, 1.45).map(lambda v: v * (1 if v > 0.75 else -1)),
       h=st.floats(0.05, 0.3), theta2=st.floats(-math.pi / 2, math.pi / 2))
def test_property_lift_is_a_contact_solution(phi, h, theta2):
    p = SwivelCarParams(phi=phi, h=h)
    state = k.kinematic_state(p, theta2)
    f, _, _ = k._lift_residual(p, state.theta1, abs(math.sin(theta2)), k._MATH)
    assert abs(f) < 1e-12
    assert state.lifted_height >= -1e-15
    assert abs(state.steering) <= math.pi / 2 + 1e-12


@settings(max_examples=40)
@given(fraction=st.floats(0.0, 1.0))
def test_property_swivel_for_step_is_smallest_clearing_angle(fraction):
    reach, _ = k.max_scalable_step(DEFAULT)
    step = fraction * reach
    theta2 = k.swivel_for_step(DEFAULT, step)
    assert k.lifted_wheel_lowest_height(DEFAULT, theta2) == pytest.approx(step, abs=1e-12)
    if theta2 > 1e-6:
        assert k.lifted_wheel_lowest_height(DEFAULT, theta2 - 1e-6) < step


def test_max_scalable_step_is_the_peak_of_the_lowest_point():
    for p in GEOMETRIES:
        grid = np.linspace(0.0, p.max_swivel_angle, 2001)
        peak = float(np.max(k.lifted_wheel_lowest_height(p, grid)))
        height, theta2 = k.max_scalable_step(p, respect_tip_over=False)
        assert height == pytest.approx(peak, abs=1e-6)
        assert k.lifted_wheel_lowest_height(p, theta2) == pytest.approx(height, abs=1e-12)


def test_tip_over_limits_the_step_when_the_apex_would_pass_the_rear_axle():
    p = SwivelCarParams(phi=1.4, h=0.3, l=0.12, r=0.03)
    free, _ = k.max_scalable_step(p, respect_tip_over=False)
    safe, theta2 = k.max_scalable_step(p, respect_tip_over=True)
    assert safe < free
    assert 0.0 < k.tip_over_margin(p, k.lift_angle(p, theta2)) < 1e-3
    with pytest.raises(ValueError, match='out of reach'):
        k.swivel_for_step(p, (safe + free) / 2)


def test_margins_follow_eqs_72_and_75():
    assert k.tip_over_margin(DEFAULT, 0.0) == pytest.approx(math.pi / 2 - DEFAULT.phi / 2)
    assert k.tip_over_margin(DEFAULT, math.pi / 2 - DEFAULT.phi / 2) == pytest.approx(0.0)
    assert k.interference_margin(DEFAULT, 0.0) == pytest.approx(
        DEFAULT.wheelbase - DEFAULT.h * math.sin(DEFAULT.phi / 2))
    # A float takes the scalar path (no numpy): the same numbers as an array.
    theta1 = [0.0, 0.2, -0.1]
    assert k.tip_over_margin(DEFAULT, np.array(theta1)).tolist() == [
        k.tip_over_margin(DEFAULT, t) for t in theta1]


@pytest.mark.parametrize('func', [k.lift_angle, k.steering_angle, k.contact_point,
                                  k.lifted_wheel_lowest_height, k.kinematic_state,
                                  k.lift_angle_derivative, k.forward_kinematics])
@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf, 1.6, -2.0,
                                 np.array([0.1, math.nan])])
def test_bad_swivel_angles_raise(func, bad):
    with pytest.raises(ValueError, match='theta2'):
        func(DEFAULT, bad)


@pytest.mark.parametrize('bad', [math.nan, math.inf, 1.6, -1.58, np.array([0.0, math.nan])])
def test_bad_steering_raises(bad):
    with pytest.raises(ValueError, match='steering'):
        k.swivel_for_steering(DEFAULT, bad)


@pytest.mark.parametrize('bad', [math.nan, -0.01, 1.0, np.array([0.01, -1e-9])])
def test_bad_step_raises(bad):
    with pytest.raises(ValueError, match='step_height'):
        k.swivel_for_step(DEFAULT, bad)


@pytest.mark.parametrize('func', [k.tip_over_margin, k.interference_margin])
def test_bad_theta1_raises(func):
    with pytest.raises(ValueError, match='theta1'):
        func(DEFAULT, math.nan)


def test_limited_joint_range_is_respected():
    p = SwivelCarParams(max_swivel_angle=1.0, swivel_limit=1.0)
    with pytest.raises(ValueError, match='theta2'):
        k.lift_angle(p, 1.01)
    with pytest.raises(ValueError, match='steering'):
        k.swivel_for_steering(p, k.max_steering_angle(p) + 0.01)


def test_scalar_in_scalar_out_and_shape_preserved():
    assert isinstance(k.lift_angle(DEFAULT, 0.3), float)
    out = k.steering_angle(DEFAULT, np.zeros((3, 4)))
    assert out.shape == (3, 4)
    assert k.forward_kinematics(DEFAULT, np.zeros((2, 5))).o3.shape == (2, 5, 4, 4)


@settings(max_examples=40)
@given(phi=st.floats(0.1, 1.4).map(lambda v: v if v > 0.75 else -v),
       h=st.floats(0.05, 0.3), fraction=st.floats(-1.0, 1.0))
def test_property_swivel_for_steering_inverts_steering(phi, h, fraction):
    p = SwivelCarParams(phi=phi, h=h)
    wanted = fraction * k.max_steering_angle(p)
    theta2 = k.swivel_for_steering(p, wanted)
    assert abs(theta2) <= p.max_swivel_angle
    assert k.steering_angle(p, theta2) == pytest.approx(wanted, abs=1e-10)
