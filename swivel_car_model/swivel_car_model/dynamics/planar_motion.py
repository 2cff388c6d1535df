"""
Planar motion of the swivel car with nonholonomic constraints (thesis II.D, eqs. 29-44).

Re-derived in base_link terms: the rear axle middle ``(x, y)`` with heading ``yaw`` is free,
the rear wheels and the steering wheel may roll but not skid sideways, and the swivel angle
moves the steering wheel's contact point ``(a, b)``, its heading ``delta`` and the mass points
along the exact kinematics (the thesis' prismatic joints ``u, v`` and revolute ``alpha``, eqs.
34-35, driven perfectly instead of through the inverse-dynamics controller of eq. 36). The
masses: the body (``mass - 4 wheel_mass``) at the apex' ground projection and one
``wheel_mass`` at each wheel centre's projection. Equations of motion (d'Alembert with
Lagrange multipliers)::

    M(q, t) q_ddot + f(q, q_dot, t) = A(q, t)^T lambda,   A q_dot + a_0(t) = 0,

integrated as an index-1 DAE (the constraints differentiated once and solved together with
the accelerations for the multipliers; solve_ivp, tight tolerances, the residual of the
velocity constraints reported). A swivel move starting from rest is an impulsive start: the
initial velocities follow from Gauss' principle (least kinetic energy subject to the
constraints). Without external forces in the plane the path is independent of the swivel
rate, so :func:`swivel_pose_drift` is a property of the geometry alone.
"""

from __future__ import annotations

from dataclasses import dataclass
import functools
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

from swivel_car_model import kinematics
from swivel_car_model.dynamics._common import finite, positive, PROFILE_SIZE, swivel_angle
from swivel_car_model.params import SwivelCarParams

_DRIFT_SAMPLES = 257  # samples of the cached drift spline over [0, max_swivel_angle]


@functools.lru_cache(maxsize=16)
def _planar_profile(p: SwivelCarParams) -> tuple[np.ndarray, np.ndarray]:
    """Knots [rad] and cubic coefficients (4, knots - 1, 9) of the swivel's profile spline."""
    # Columns: contact a, b, steering delta, then the body points (x, y): apex projection,
    # front right wheel centre, front left wheel centre.
    theta2 = np.linspace(0.0, p.max_swivel_angle, PROFILE_SIZE)
    state = kinematics.kinematic_state(p, theta2)
    frames = kinematics.forward_kinematics(p, theta2, state.theta1)
    apex_x = p.l * np.cos(state.theta1 + p.phi / 2.0)
    columns = [state.contact_x, state.contact_y, state.steering, apex_x, np.zeros_like(apex_x),
               frames.o3[:, 0, 3], frames.o3[:, 1, 3], frames.o3_left[:, 0, 3],
               frames.o3_left[:, 1, 3]]
    spline = CubicSpline(theta2, np.stack(columns, axis=-1))
    return spline.x, spline.c


# which profile columns are lateral (y-like, odd under theta2 -> -theta2)
_MIRROR = np.array([1.0, -1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0])


def _profile_at(p: SwivelCarParams, theta2: float, rate: float, side: float):
    """
    Profile values and their time derivatives at swivel angle theta2 moving at ``rate``.

    ``side`` (+1 / -1) says which side of zero the move lies on (which wheel steers). The
    spline's cubic pieces are evaluated directly: this runs once per DAE right-hand side.
    """
    knots, coefficients = _planar_profile(p)
    s = min(max(side * theta2, 0.0), p.max_swivel_angle)
    i = min(max(int(knots.searchsorted(s)) - 1, 0), len(knots) - 2)
    dx = s - float(knots[i])
    c0, c1, c2, c3 = coefficients[:, i, :]
    mirror = _MIRROR if side < 0.0 else 1.0
    value = mirror * (((c0 * dx + c1) * dx + c2) * dx + c3)
    d1 = mirror * side * ((3.0 * c0 * dx + 2.0 * c1) * dx + c2)
    d2 = mirror * (6.0 * c0 * dx + 2.0 * c1)
    return value, d1 * rate, d2 * rate * rate


@dataclass(frozen=True)
class _PlanarModel:
    masses: tuple[float, ...]  # [kg] body, rear right, rear left, front right, front left wheel
    yaw_inertia: float  # [kg m^2] of the body about its own mass point

    @staticmethod
    def of(p: SwivelCarParams, yaw_inertia: float | None) -> '_PlanarModel':
        body = p.mass - 4.0 * p.wheel_mass
        if yaw_inertia is None:
            # uniform plate of the car's footprint (the thesis gives no I_car)
            yaw_inertia = body * (p.wheelbase ** 2 + (2.0 * p.h) ** 2) / 12.0
        return _PlanarModel((float(body),) + (float(p.wheel_mass),) * 4, float(yaw_inertia))


def _points(p: SwivelCarParams, value: list[float], d1: list[float],
            d2: list[float]) -> tuple[tuple[float, ...], ...]:
    """
    Body-frame mass points, in ``_PlanarModel.masses``' order, and their time derivatives.

    Each ``(x, y, dx/dt, dy/dt, d2x/dt2, d2y/dt2)`` [m, m/s, m/s^2]. In scalars: the DAE's
    right-hand side reads them, where numpy's per-call cost on 2-vectors made it three times
    slower.
    """
    rest = (0.0, 0.0, 0.0, 0.0)
    return ((value[3], value[4], d1[3], d1[4], d2[3], d2[4]),
            (0.0, -p.h) + rest, (0.0, p.h) + rest,
            (value[5], value[6], d1[5], d1[6], d2[5], d2[6]),
            (value[7], value[8], d1[7], d1[8], d2[7], d2[8]))


def _planar_system(p, model, q, qd, value, d1, d2):
    """Mass matrix, bias forces, constraint matrix and its velocity/acceleration terms."""
    yaw, vx, vy, wz = float(q[2]), float(qd[0]), float(qd[1]), float(qd[2])
    c, s = math.cos(yaw), math.sin(yaw)
    v, v1, v2 = value.tolist(), d1.tolist(), d2.tolist()
    first_x = first_y = inertia = force_x = force_y = torque = 0.0
    wz2 = wz * wz
    for m, (px, py, dpx, dpy, ddpx, ddpy) in zip(model.masses, _points(p, v, v1, v2)):
        rx, ry = c * px - s * py, s * px + c * py
        rdx, rdy = c * dpx - s * dpy, s * dpx + c * dpy
        rddx, rddy = c * ddpx - s * ddpy, s * ddpx + c * ddpy
        extra_x = -wz2 * rx - 2.0 * wz * rdy + rddx
        extra_y = -wz2 * ry + 2.0 * wz * rdx + rddy
        first_x -= m * ry
        first_y += m * rx
        inertia += m * (rx * rx + ry * ry)
        force_x += m * extra_x
        force_y += m * extra_y
        torque += m * (rx * extra_y - ry * extra_x)
    total = sum(model.masses)
    mass_matrix = np.array([[total, 0.0, first_x], [0.0, total, first_y],
                            [first_x, first_y, inertia + model.yaw_inertia]])
    bias = np.array([force_x, force_y, torque])
    # rear axle: no lateral velocity of the axle middle (normal (-sin yaw, cos yaw));
    # steering wheel contact: no velocity across its rolling direction (normal at psi)
    psi = yaw + v[2]
    cp, sp = math.cos(psi), math.sin(psi)
    cx, cy = c * v[0] - s * v[1], s * v[0] + c * v[1]
    cdx, cdy = c * v1[0] - s * v1[1], s * v1[0] + c * v1[1]
    cddx, cddy = c * v2[0] - s * v2[1], s * v2[0] + c * v2[1]
    a_matrix = np.array([[-s, c, 0.0], [-sp, cp, sp * cy + cp * cx]])
    a_zero = np.array([0.0, -sp * cdx + cp * cdy])
    # d/dt of the constraint rows applied to qd, plus the prescribed terms
    rate_front = -(wz + v1[2])
    w_contact_x, w_contact_y = vx - wz * cy + cdx, vy + wz * cx + cdy
    accel_bias = np.array([
        -wz * (c * vx + s * vy),
        rate_front * (cp * w_contact_x + sp * w_contact_y)
        - sp * (-wz2 * cx - 2.0 * wz * cdy + cddx) + cp * (-wz2 * cy + 2.0 * wz * cdx + cddy)])
    return mass_matrix, bias, a_matrix, a_zero, accel_bias


def _kkt_solve(mass_matrix, rhs_top, a_matrix, rhs_bottom):
    kkt = np.zeros((5, 5))
    kkt[:3, :3] = mass_matrix
    kkt[:3, 3:] = -a_matrix.T
    kkt[3:, :3] = a_matrix
    sol = np.linalg.solve(kkt, np.concatenate([rhs_top, rhs_bottom]))
    return sol[:3], sol[3:]


@dataclass(frozen=True)
class PlanarResult:
    """Pose of base_link in the frame it had at the start, over time."""

    time: np.ndarray  # [s]
    theta2: np.ndarray  # [rad]
    x: np.ndarray  # [m]
    y: np.ndarray  # [m]
    yaw: np.ndarray  # [rad]
    velocity: np.ndarray  # (N, 3) [m/s, m/s, rad/s] world-frame rates of (x, y, yaw)
    multipliers: np.ndarray  # (N, 2) [N] lateral forces at the rear axle and steering wheel
    kinetic_energy: np.ndarray  # [J]
    max_constraint_residual: float  # [m/s] largest |A q_dot + a_0| along the run


def _kinetic_energy(p, model, q, qd, value, d1):
    yaw, vx, vy, wz = float(q[2]), float(qd[0]), float(qd[1]), float(qd[2])
    c, s = math.cos(yaw), math.sin(yaw)
    v, v1 = value.tolist(), d1.tolist()
    energy = 0.5 * model.yaw_inertia * wz * wz
    for m, (px, py, dpx, dpy, _, _) in zip(model.masses, _points(p, v, v1, v1)):
        # qd_xy + wz J R p + R dp/dt
        vel_x = vx - wz * (s * px + c * py) + c * dpx - s * dpy
        vel_y = vy + wz * (c * px - s * py) + s * dpx + c * dpy
        energy += 0.5 * m * (vel_x * vel_x + vel_y * vel_y)
    return energy


def _simulate_planar(p: SwivelCarParams, theta2_start: float, rate: float, duration: float,
                     qd0: np.ndarray, samples: int, yaw_inertia: float | None,
                     rtol: float) -> PlanarResult:
    model = _PlanarModel.of(p, yaw_inertia)
    q0 = np.zeros(3)

    def theta2_at(t: float) -> float:
        return theta2_start + rate * t

    side = -1.0 if (theta2_start < 0.0 or (theta2_start == 0.0 and rate < 0.0)) else 1.0
    value, d1, d2 = _profile_at(p, theta2_start, rate, side)
    mass_matrix, _, a_matrix, a_zero, _ = _planar_system(p, model, q0, qd0, value, d1, d2)
    qd_start, _ = _kkt_solve(mass_matrix, mass_matrix @ qd0, a_matrix, -a_zero)

    def accel(t: float, state: np.ndarray):
        q, qd = state[:3], state[3:]
        value, d1, d2 = _profile_at(p, theta2_at(t), rate, side)
        mass_matrix, bias, a_matrix, a_zero, accel_bias = _planar_system(
            p, model, q, qd, value, d1, d2)
        qdd, lam = _kkt_solve(mass_matrix, -bias, a_matrix, -accel_bias)
        return qdd, lam, value, d1, a_matrix @ qd + a_zero

    def rhs(t: float, state: np.ndarray) -> np.ndarray:
        return np.concatenate([state[3:], accel(t, state)[0]])

    t_eval = np.linspace(0.0, duration, samples)
    sol = solve_ivp(rhs, (0.0, duration), np.concatenate([q0, qd_start]), t_eval=t_eval,
                    method='DOP853', rtol=rtol, atol=rtol * 1e-2)
    if not sol.success:
        raise RuntimeError(f'planar DAE integration failed: {sol.message}')
    lams, energies, residual = [], [], 0.0
    for i, t in enumerate(sol.t):
        state = sol.y[:, i]
        _, lam, value, d1, violation = accel(t, state)
        lams.append(lam)
        energies.append(_kinetic_energy(p, model, state[:3], state[3:], value, d1))
        residual = max(residual, float(np.max(np.abs(violation))))
    return PlanarResult(time=sol.t, theta2=theta2_at(sol.t), x=sol.y[0], y=sol.y[1],
                        yaw=sol.y[2], velocity=sol.y[3:].T, multipliers=np.array(lams),
                        kinetic_energy=np.array(energies), max_constraint_residual=residual)


def simulate_planar_swivel(p: SwivelCarParams, theta2_from: float = 0.0,
                           theta2_to: float = math.pi / 2, rate: float = 0.05,
                           samples: int = 316, yaw_inertia: float | None = None,
                           rtol: float = 1e-9) -> PlanarResult:
    """
    Simulate the car, at rest, while the swivel turns at a constant rate (Figs. 36-38).

    Thesis setting: 0 -> pi/2 at 0.05 rad/s over 31.5 s. The move must not cross zero.

    Parameters
    ----------
    p : SwivelCarParams
        The car's model parameters.
    theta2_from, theta2_to : float
        Initial and final swivel angle. # [rad]
    rate : float
        Magnitude of the swivel rate. # [rad/s]
    samples : int
        Number of output samples over the move.
    yaw_inertia : float, optional
        Yaw inertia of the body about its mass point; default a uniform plate of the
        footprint. # [kg m^2]
    rtol : float
        Relative tolerance of the integrator.

    """
    start = swivel_angle(p, 'theta2_from', theta2_from)
    end = swivel_angle(p, 'theta2_to', theta2_to)
    rate = positive('rate', rate)
    if start * end < 0.0:
        raise ValueError('a planar swivel move must not cross theta2 = 0; split it')
    if start == end:
        raise ValueError('theta2_from and theta2_to must differ')
    signed = math.copysign(rate, end - start)
    return _simulate_planar(p, start, signed, abs(end - start) / rate, np.zeros(3), samples,
                            yaw_inertia, rtol)


def simulate_planar_coast(p: SwivelCarParams, theta2: float, velocity: tuple[float, float, float],
                          duration: float, samples: int = 201,
                          yaw_inertia: float | None = None, rtol: float = 1e-10) -> PlanarResult:
    """
    Simulate the unactuated DAE: swivel fixed, a push ``(vx, vy, yaw rate)``, free rolling.

    The initial velocity is projected onto the constraints (an impulsive start); the kinetic
    energy is then a constant of the motion, since ideal nonholonomic constraints do no work.
    """
    theta2 = swivel_angle(p, 'theta2', theta2)
    duration = positive('duration', duration)
    qd0 = np.array([finite('velocity', v) for v in velocity])
    return _simulate_planar(p, theta2, 0.0, duration, qd0, samples, yaw_inertia, rtol)


@functools.lru_cache(maxsize=16)
def _drift_from_zero(p: SwivelCarParams) -> CubicSpline:
    """
    Return the pose after a move from rest at 0 to theta2 >= 0, for every theta2 at once.

    The run 0 -> max_swivel_angle passes through each of them.
    """
    # rtol 1e-8: within 1e-7 m and rad of the default 1e-9, in under a third of its time (0.3 s).
    run = simulate_planar_swivel(p, 0.0, p.max_swivel_angle, rate=1.0, samples=_DRIFT_SAMPLES,
                                 rtol=1e-8)
    return CubicSpline(run.theta2, np.stack([run.x, run.y, run.yaw], axis=-1))


def _segment_drift(p: SwivelCarParams, start: float, end: float) -> np.ndarray:
    if start == 0.0:
        side = 1.0 if end > 0.0 else -1.0
        return np.array([1.0, side, side]) * _drift_from_zero(p)(abs(end))
    run = simulate_planar_swivel(p, start, end, rate=1.0, samples=2, rtol=1e-8)
    return np.array([run.x[-1], run.y[-1], run.yaw[-1]])


@functools.lru_cache(maxsize=512)
def _drift(p: SwivelCarParams, theta2_from: float, theta2_to: float) -> tuple[float, float, float]:
    pose = np.zeros(3)
    bounds = [theta2_from, theta2_to]
    if theta2_from * theta2_to < 0.0:
        bounds = [theta2_from, 0.0, theta2_to]
    for a, b in zip(bounds[:-1], bounds[1:]):
        # each segment starts from rest: the swivel stops at zero before reversing
        dx, dy, dyaw = _segment_drift(p, a, b)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        pose = pose + np.array([c * dx - s * dy, s * dx + c * dy, dyaw])
    return float(pose[0]), float(pose[1]), float(pose[2])


def swivel_pose_drift(p: SwivelCarParams, theta2_from: float,
                      theta2_to: float) -> tuple[float, float, float]:
    """
    Pose change of base_link caused by a swivel move from rest (wheels rolling freely).

    Rate independent (see the module docstring); the pose is taken when the swivel reaches
    ``theta2_to`` (after that the car coasts unless its wheels are braked). A move through
    zero is two moves, each from rest. Moves from zero come from one cached run over the whole
    range (a spline; within 3e-7 m and rad of an rtol 1e-12 run); others are integrated once
    and cached per arguments (rounded to 1e-6 rad).

    Returns
    -------
    (dx [m], dy [m], dyaw [rad])
        In the base_link frame at the start of the move.

    """
    a = round(swivel_angle(p, 'theta2_from', theta2_from), 6)
    b = round(swivel_angle(p, 'theta2_to', theta2_to), 6)
    if a == b:
        return 0.0, 0.0, 0.0
    return _drift(p, a, b)
