"""Climbing geometry against independent computations (rim sampling, odometry, virtual work)."""

import math

import numpy as np
import pytest

from swivel_car_model import climbing as c
from swivel_car_model import kinematics as k
from swivel_car_model import planar
from swivel_car_model.params import SwivelCarParams

P = SwivelCarParams()
NEG = SwivelCarParams(phi=-math.pi / 3)
ANGLES = np.linspace(-1.5, 1.5, 13)


def rim_points(centre, axle, r, n=20000):
    axle = axle / np.linalg.norm(axle)
    u = np.cross(axle, [0.0, 0.0, 1.0])
    if np.linalg.norm(u) < 1e-9:
        u = np.cross(axle, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(axle, u)
    psi = np.linspace(0.0, 2 * math.pi, n)[:, None]
    return centre + r * (np.cos(psi) * u + np.sin(psi) * v)


@pytest.mark.parametrize('p', [P, NEG])
def test_extreme_points_match_rim_sampling(p):
    for theta2 in ANGLES:
        frames = k.forward_kinematics(p, theta2)
        steering, lifted = ((frames.o3, frames.o3_left) if theta2 >= 0
                            else (frames.o3_left, frames.o3))
        lifted_rim = rim_points(lifted[:3, 3], lifted[:3, 2], p.r)
        steering_rim = rim_points(steering[:3, 3], steering[:3, 2], p.r)
        low = lifted_rim[np.argmin(lifted_rim[:, 2])]
        front = steering_rim[np.argmax(steering_rim[:, 0])]
        lowest = c.lifted_wheel_lowest_point(p, theta2)
        foremost = c.steering_wheel_front_point(p, theta2)
        # the sampled extreme value is exact to O(step^2), its location only to O(step)
        assert lowest[2] == pytest.approx(low[2], abs=1e-8)
        assert foremost[0] == pytest.approx(front[0], abs=1e-8)
        np.testing.assert_allclose(lowest, low, atol=5e-5)
        np.testing.assert_allclose(foremost, front, atol=5e-5)


def test_lowest_point_height_agrees_with_kinematics():
    np.testing.assert_allclose(c.lifted_wheel_lowest_point(P, ANGLES)[:, 2] + P.r,
                               k.lifted_wheel_lowest_height(P, ANGLES), atol=1e-12)


def test_induced_torque_at_rest_is_eq_89_corrected():
    for p, sign in ((NEG, 1.0), (P, -1.0)):
        expected = sign * p.h * (5.0 / p.r) * math.sin(abs(p.phi) / 2)
        assert c.induced_swivel_torque(p, 5.0) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize('theta2', [0.0, 0.3, 0.9, -0.6, 1.4])
def test_induced_torque_is_the_virtual_work_of_the_reaction(theta2):
    # rotate the front T about the swivel axis with the body pitch held: tau = F . dC/dtheta2
    theta1 = k.lift_angle(NEG, theta2)
    eps = 1e-6

    def lifted_centre(t2):
        frames = k.forward_kinematics(NEG, t2, theta1)
        return (frames.o3_left if theta2 >= 0 else frames.o3)[:3, 3]

    d_centre = (lifted_centre(theta2 + eps) - lifted_centre(theta2 - eps)) / (2 * eps)
    force = np.array([-4.0 / NEG.r, 0.0, 0.0])
    sign = 1.0 if theta2 >= 0 else -1.0
    assert c.induced_swivel_torque(NEG, 4.0, theta2) == pytest.approx(
        sign * float(force @ d_centre), abs=1e-6)


def test_induced_torque_grows_with_h_and_shrinks_with_r():
    base = c.induced_swivel_torque(NEG, 5.0)
    longer = c.induced_swivel_torque(SwivelCarParams(phi=NEG.phi, h=0.2), 5.0)
    bigger = c.induced_swivel_torque(SwivelCarParams(phi=NEG.phi, r=0.1), 5.0)
    assert longer > base > bigger > 0.0


@pytest.mark.parametrize('bad', [math.nan, -1.0])
def test_induced_torque_bad_drive_torque(bad):
    with pytest.raises(ValueError, match='drive_torque'):
        c.induced_swivel_torque(NEG, bad)


def test_induced_torque_bad_swivel():
    with pytest.raises(ValueError, match='theta2'):
        c.induced_swivel_torque(NEG, 1.0, 2.0)


def test_min_approach_angle_range_and_step_version():
    angles = c.min_approach_angle(NEG, np.linspace(0.0, 1.5, 31))
    assert np.all((angles >= 0.0) & (angles <= math.pi / 2))
    assert np.all(np.diff(angles) > 0.0)
    step = 0.05
    assert c.min_approach_angle_for_step(NEG, step) == pytest.approx(
        c.min_approach_angle(NEG, k.swivel_for_step(NEG, step)))
    with pytest.raises(ValueError, match='step_height'):
        c.min_approach_angle_for_step(NEG, -0.1)


@pytest.mark.parametrize('theta_i,gamma', [(0.8, 0.0), (-0.5, 0.2), (0.3, 1.0)])
def test_approach_plan_lands_the_lifted_wheel_on_the_edge(theta_i, gamma):
    step = 0.05
    plan = c.approach_for_step(P, step, gamma, theta_i, include_drift=False)
    assert k.lifted_wheel_lowest_height(P, plan.theta2) == pytest.approx(step, abs=1e-9)
    odom = planar.OffsetTricycleOdometry(P)
    odom.set_pose(0.0, 0.0, theta_i)
    n = 4000
    speed = 0.1  # [m/s]
    dt = plan.arc_length / speed / n
    for _ in range(n):
        odom.update(plan.theta2, 0.0, planar.wheel_rate_for_speed(P, speed), dt)
    assert odom.yaw == pytest.approx(gamma, abs=1e-6)
    low = c.lifted_wheel_lowest_point(P, plan.theta2)
    x_low = odom.x + math.cos(odom.yaw) * low[0] - math.sin(odom.yaw) * low[1]
    assert x_low == pytest.approx(plan.distance, abs=1e-6)


def test_approach_plan_with_drift_turns_the_same_way():
    plan = c.approach_for_step(P, 0.05, 0.0, 0.8)
    bare = c.approach_for_step(P, 0.05, 0.0, 0.8, include_drift=False)
    assert plan.theta2 == bare.theta2
    assert plan.arc_angle != bare.arc_angle


@pytest.mark.parametrize('args', [(0.05, 0.3, 0.3), (math.nan, 0.0, 0.5), (0.05, 0.0, math.nan),
                                  (1.0, 0.0, 0.5), (0.0, 0.0, 0.5)])
def test_approach_bad_input(args):
    with pytest.raises(ValueError):
        c.approach_for_step(P, *args, include_drift=False)
