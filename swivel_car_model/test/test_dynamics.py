"""Dynamics: energy balances, symmetries, the unactuated DAE's invariants, bad input."""

import dataclasses
import math

import numpy as np
import pytest

from swivel_car_model import dynamics as d
from swivel_car_model import kinematics as k
from swivel_car_model import planar
from swivel_car_model.dynamics import car_like
from swivel_car_model.params import SwivelCarParams

P = SwivelCarParams()


def apex_potential(p, theta2):
    """Return m g times the apex height above its rest height, from the kinematics [J]."""
    theta1 = k.lift_angle(p, theta2)
    return p.mass * d.GRAVITY * p.l * (np.sin(theta1 + p.phi / 2) - math.sin(p.phi / 2))


def test_gravity_torque_is_the_derivative_of_the_apex_potential():
    t = np.array([0.05, 0.3, 0.8, 1.2, 1.5])
    eps = 1e-6
    numeric = (apex_potential(P, t + eps) - apex_potential(P, t - eps)) / (2 * eps)
    np.testing.assert_allclose(d.swivel_gravity_torque(P, t), numeric, atol=1e-6)
    np.testing.assert_allclose(d.swivel_gravity_torque(P, -t), -numeric, atol=1e-6)


def test_holding_torque_at_zero_is_m_g_cos_half_phi_h_over_two():
    expected = P.mass * d.GRAVITY * math.cos(P.phi / 2) * P.h / 2
    assert d.swivel_gravity_torque(P, 1e-12) == pytest.approx(expected, rel=1e-9)


def test_generalized_inertia():
    t = 0.4
    expected = P.inertia * k.lift_angle_derivative(P, t) ** 2 + 2 * P.wheel_mass * P.h ** 2
    assert d.swivel_generalized_inertia(P, t) == pytest.approx(expected)


@pytest.mark.parametrize('target', [0.5, -0.5, 1.2])
def test_swivel_move_settles_and_its_work_is_the_potential_gain(target):
    move = d.simulate_swivel_move(P, target, duration=30.0, stop_when_settled=True)
    assert move.theta2[-1] == pytest.approx(target, abs=1e-4)
    assert move.work[-1] == pytest.approx(float(apex_potential(P, target)), rel=2e-3)
    assert move.total_energy >= move.work[-1] - 1e-9
    assert move.peak_torque == pytest.approx(float(np.max(np.abs(move.torque))))


def test_swivel_move_is_odd_in_the_target():
    up = d.simulate_swivel_move(P, 0.7, duration=5.0)
    down = d.simulate_swivel_move(P, -0.7, duration=5.0)
    np.testing.assert_allclose(down.theta2, -up.theta2, atol=1e-6)
    np.testing.assert_allclose(down.torque, -up.torque, atol=1e-4)


def test_joint_stays_at_zero_until_the_pid_beats_the_holding_torque():
    move = d.simulate_swivel_move(P, 0.1, duration=2.0)  # Kp e + Ki int e << 13 N m
    assert np.all(move.theta2 == 0.0)
    assert move.total_energy == 0.0


def test_a_ramped_set_point_takes_the_proportional_kick_off_the_peak():
    # Gains 150/200/8 (the robot's): a step to 0.3 rad kicks kp * 0.3 = 45 N m at once; at
    # 0.6 rad/s the set point leads the swivel by little more than the holding torque needs.
    p = dataclasses.replace(P, kp=150.0, ki=200.0, kd=8.0)
    stepped = d.simulate_swivel_move(p, 0.3, duration=10.0)
    ramped = d.simulate_swivel_move(p, 0.3, duration=10.0, max_rate=0.6)
    assert stepped.peak_torque == pytest.approx(45.0, rel=1e-3)
    holding = float(d.swivel_gravity_torque(p, 1e-12))
    assert holding <= ramped.peak_torque < 1.3 * holding
    assert ramped.theta2[-1] == pytest.approx(0.3, abs=1e-3)
    assert d.climb_torque_energy(p, 0.08, 0.6)[0] == pytest.approx(ramped.peak_torque,
                                                                   rel=0.1)


def test_climb_cost_covers_the_holding_torque_and_twice_the_lift_work():
    peak, energy = d.climb_torque_energy(P, 0.05)
    assert peak >= d.swivel_gravity_torque(P, 1e-12)
    theta2 = k.swivel_for_step(P, 0.05)
    assert energy >= 2 * float(apex_potential(P, theta2)) * (1 - 1e-3)
    assert d.climb_torque_energy(P, 0.0) == (0.0, 0.0)


@pytest.mark.parametrize('kwargs', [{'theta2_target': math.nan}, {'theta2_target': 2.0},
                                    {'theta2_target': 0.3, 'theta2_start': -0.2},
                                    {'theta2_target': 0.3, 'duration': 0.0},
                                    {'theta2_target': 0.3, 'samples': 1}])
def test_swivel_move_bad_input(kwargs):
    with pytest.raises(ValueError):
        d.simulate_swivel_move(P, **kwargs)


@pytest.mark.parametrize('step', [math.nan, -0.01, 1.0])
def test_climb_bad_input(step):
    with pytest.raises(ValueError, match='step_height'):
        d.climb_torque_energy(P, step)


def test_car_like_climb_work_is_potential_plus_kinetic_energy():
    c = d.CarLikeParams(step_height=0.012)
    run = d.simulate_car_like_climb(c)
    _, y0, *_ = car_like._crank_geometry(c, np.array(run.crank_angle[0]))
    _, y1, *_ = car_like._crank_geometry(c, np.array(run.crank_angle[-1]))
    rate = np.gradient(run.crank_angle, run.time)[-1]
    inertia, _ = car_like._crank_profile(c)[1](run.crank_angle[-1])
    expected = c.mass * d.GRAVITY * (y1 - y0) + 0.5 * inertia * rate ** 2
    assert run.total_energy == pytest.approx(float(expected), rel=1e-2)
    assert run.peak_torque == pytest.approx(
        c.kp * (c.goal - math.asin((c.wheel_radius - c.step_height) / c.wheel_radius)))


@pytest.mark.parametrize('field,value', [('mass', -1.0), ('step_height', 0.1),
                                         ('kp', math.nan)])
def test_car_like_params_validate(field, value):
    with pytest.raises(ValueError, match=field):
        d.CarLikeParams(**{field: value})


@pytest.fixture(scope='module')
def thesis_run():
    return d.simulate_planar_swivel(P)


def test_planar_run_keeps_the_constraints(thesis_run):
    assert thesis_run.max_constraint_residual < 1e-7
    assert thesis_run.time[-1] == pytest.approx(math.pi / 2 / 0.05)
    assert thesis_run.x[-1] < 0.0  # backwards, as the thesis says
    assert thesis_run.yaw[-1] < 0.0  # clockwise, as the thesis says


def test_planar_run_is_rate_independent(thesis_run):
    fast = d.simulate_planar_swivel(P, rate=1.0, samples=2)
    # Each run's end pose against an rtol 1e-12 run: 1.5e-7 (thesis rate) and 4.8e-8 m and
    # rad apart, so up to 2e-7 between them; 1e-6 gives fivefold margin for another CPU.
    assert (fast.x[-1], fast.y[-1], fast.yaw[-1]) == pytest.approx(
        (thesis_run.x[-1], thesis_run.y[-1], thesis_run.yaw[-1]), abs=1e-6)


def test_unactuated_dae_conserves_kinetic_energy():
    run = d.simulate_planar_coast(P, 0.6, (0.3, 0.0, 0.1), duration=10.0)
    energy = run.kinetic_energy
    assert energy[0] > 0.0
    np.testing.assert_allclose(energy, energy[0], rtol=1e-8)
    assert run.max_constraint_residual < 1e-8


@pytest.mark.parametrize('theta2', [0.0, 0.4, -0.9, 1.3])
def test_coasting_follows_the_offset_tricycle_curvature(theta2):
    run = d.simulate_planar_coast(P, theta2, (0.2, 0.0, 0.0), duration=3.0)
    vx, vy, wz = run.velocity[-1]
    speed = math.hypot(vx, vy)
    assert wz / speed == pytest.approx(planar.curvature_for_swivel(P, theta2), abs=1e-7)
    # the rear axle never moves sideways
    lateral = -np.sin(run.yaw) * run.velocity[:, 0] + np.cos(run.yaw) * run.velocity[:, 1]
    assert np.max(np.abs(lateral)) < 1e-8


def test_swivel_pose_drift_symmetry_and_zero_move():
    dx, dy, dyaw = d.swivel_pose_drift(P, 0.0, 0.8)
    assert d.swivel_pose_drift(P, 0.0, -0.8) == pytest.approx((dx, -dy, -dyaw), abs=1e-7)
    assert d.swivel_pose_drift(P, 0.5, 0.5) == (0.0, 0.0, 0.0)
    assert dyaw < 0.0


def test_swivel_pose_drift_through_zero_is_two_moves():
    first = d.swivel_pose_drift(P, 0.4, 0.0)
    second = d.swivel_pose_drift(P, 0.0, -0.4)
    dx, dy, dyaw = d.swivel_pose_drift(P, 0.4, -0.4)
    c, s = math.cos(first[2]), math.sin(first[2])
    expected = (first[0] + c * second[0] - s * second[1],
                first[1] + s * second[0] + c * second[1], first[2] + second[2])
    assert (dx, dy, dyaw) == pytest.approx(expected, abs=1e-9)


def test_bigger_shaft_gives_bigger_yaw_drift():
    # Half the range shows it at a tenth of the cost: the integration stiffens towards pi/2.
    small = d.simulate_planar_swivel(dataclasses.replace(P, h=0.1), 0.0, 0.7, rate=1.0,
                                     samples=2)
    big = d.simulate_planar_swivel(dataclasses.replace(P, h=0.2), 0.0, 0.7, rate=1.0, samples=2)
    assert abs(big.yaw[-1]) > abs(small.yaw[-1])


@pytest.mark.parametrize('args', [(math.nan, 0.3), (0.0, 1.6), (0.3, math.inf)])
def test_swivel_pose_drift_bad_input(args):
    with pytest.raises(ValueError, match='theta2'):
        d.swivel_pose_drift(P, *args)


@pytest.mark.parametrize('kwargs', [{'theta2_from': -0.3, 'theta2_to': 0.3},
                                    {'theta2_from': 0.3, 'theta2_to': 0.3},
                                    {'rate': 0.0}, {'rate': math.nan}])
def test_planar_swivel_bad_input(kwargs):
    with pytest.raises(ValueError):
        d.simulate_planar_swivel(P, **kwargs)


# The spline's error, measured against rtol 1e-12 runs at 44 angles over 0-1.5707 rad: at
# most 2.9e-7 m and rad (its rtol 1e-8 run plus interpolation); the direct rtol 1e-9 run
# differs from that reference by at most 4.8e-8. 1e-6 leaves a threefold margin for another
# CPU's rounding, which moves the adaptive steps.
DRIFT_SPLINE_ERROR = 1e-6  # [m], [rad]


@pytest.mark.parametrize('theta2', [0.013, 0.7, -1.2, 1.57])
def test_drift_from_zero_spline_matches_direct_integration(theta2):
    run = d.simulate_planar_swivel(P, 0.0, theta2, rate=1.0, samples=2)
    assert d.swivel_pose_drift(P, 0.0, theta2) == pytest.approx(
        (run.x[-1], run.y[-1], run.yaw[-1]), abs=DRIFT_SPLINE_ERROR)
