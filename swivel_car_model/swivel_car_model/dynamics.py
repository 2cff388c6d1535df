"""
Dynamics of the swivel car: swivel torque, car-like baseline, planar nonholonomic model.

Swivel-joint torque and energy, the car-like baseline, and the planar model with
nonholonomic constraints.
Three models (thesis II.C, II.D and IV.A), each derived again; corrections to the thesis are
listed in docs/thesis_reproduction.md.

1. Steering mechanism (eqs. 17-26). The whole mass sits at the apex ``C_m`` and pitches with the
   lift angle about the rear axle, ``theta1 = theta1(theta2)`` (the lift constraint), so with the
   swivel angle as the only coordinate::

       L = 1/2 I_s theta1'(theta2)^2 theta2_dot^2 - m g (H(theta2) - H_0),
       H = l sin(theta1 + phi/2),  H_0 = l sin(phi/2),

   (eqs. 22-23 print the apex height with the complementary angle and with the ``l cos phi``
   translation of the O_1 frame, and eq. 21 has ``H_o - H_i``, which makes lifting release
   energy). Euler-Lagrange::

       J theta2_ddot + 1/2 J' theta2_dot^2 + m g l cos(theta1 + phi/2) theta1' = tau,
       J = I_s theta1'^2 + 2 m_w h^2

   (the front wheels' inertia about the swivel axis is our addition: without it ``J`` vanishes
   where the lift angle peaks).

   The PID (eq. 26) acts on the swivel angle with the derivative on the measurement,
   ``tau = Kp e + Ki int(e) - Kd theta2_dot``: eq. 26's ``+ K_D theta2_dot`` is positive
   feedback on the rate.

2. Car-like robot climbing a step as an offset slider-crank (eqs. 101-110, Table 4), solved
   as printed (eqs. 103-106 are consistent with the centre of mass at
   ``(R_w cos theta_w - c_x cos a - c_y sin a, R_w sin theta_w - c_x sin a + c_y cos a)``
   relative to the step edge), with a P controller on the crank angle (eq. 109).

3. Planar model with nonholonomic constraints (eqs. 29-44), re-derived in base_link terms: the
   rear axle middle ``(x, y)`` with heading ``yaw`` is free, the rear wheels and the steering
   wheel may roll but not skid sideways, and the swivel angle moves the steering wheel's
   contact point ``(a, b)``, its heading ``delta`` and the mass points along the exact
   kinematics (the thesis' prismatic joints ``u, v`` and revolute ``alpha``, eqs. 34-35,
   driven perfectly instead of through the inverse-dynamics controller of eq. 36). The masses:
   the body (``mass - 4 wheel_mass``) at the apex' ground projection and one ``wheel_mass`` at
   each wheel centre's projection. Equations of motion (d'Alembert with Lagrange
   multipliers)::

       M(q, t) q_ddot + f(q, q_dot, t) = A(q, t)^T lambda,   A q_dot + a_0(t) = 0,

   integrated as an index-1 DAE (the constraints differentiated once and solved together with
   the accelerations for the multipliers; solve_ivp, tight tolerances, the residual of the
   velocity constraints reported). A swivel move starting from rest is an impulsive start:
   the initial velocities follow from Gauss' principle (least kinetic energy subject to the
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
from swivel_car_model.params import SwivelCarParams

GRAVITY = 9.81  # [m/s^2]
_PROFILE_SIZE = 2001  # samples of the cached kinematic profiles over [0, max_swivel_angle]
_CLIMB_DURATION = 300.0  # [s]
_DRIFT_SAMPLES = 257  # samples of the cached drift spline over [0, max_swivel_angle]
_SETTLED = 1e-6  # [rad], [rad/s]
_HOLD_TIME = 1e-3  # [s] time constant that bleeds off a residual rate while the joint is held


def _finite(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f'{name} must be finite, got {value!r}')
    return value


def _positive(name: str, value: float) -> float:
    if _finite(name, value) <= 0.0:
        raise ValueError(f'{name} must be > 0, got {value!r}')
    return float(value)


def _swivel(p: SwivelCarParams, name: str, value: float) -> float:
    value = _finite(name, value)
    if abs(value) > p.max_swivel_angle + 1e-12:
        raise ValueError(
            f'{name} must be within +-max_swivel_angle = {p.max_swivel_angle!r} rad, '
            f'got {value!r}')
    return value


# ----------------------------------------------------------------------------------------------
# 1. Steering mechanism with PID (eqs. 17-26)

@functools.lru_cache(maxsize=16)
def _lift_profile(p: SwivelCarParams) -> CubicSpline:
    """Spline of theta1(|theta2|) with exact first derivatives (Hermite) on [0, max]."""
    theta2 = np.linspace(0.0, p.max_swivel_angle, _PROFILE_SIZE)
    theta1 = kinematics.lift_angle(p, theta2)
    slope = kinematics.lift_angle_derivative(p, theta2)
    return CubicSpline(theta2, theta1, bc_type=((1, slope[0]), (1, slope[-1])))


def front_swivel_inertia(p: SwivelCarParams) -> float:
    """
    Return the inertia of the front wheels about the swivel axis, ``2 m_w h^2`` [kg m^2].

    Not in the thesis' model, whose generalized inertia ``I_s theta1'^2`` vanishes where the
    lift angle peaks (the equation of motion is singular there).
    """
    return 2.0 * p.wheel_mass * p.h ** 2


def swivel_generalized_inertia(p: SwivelCarParams, theta2: float) -> float:
    """Return ``J = I_s (d theta1 / d theta2)^2 + 2 m_w h^2``, the swivel's inertia [kg m^2]."""
    return p.inertia * kinematics.lift_angle_derivative(p, theta2) ** 2 + front_swivel_inertia(p)


def swivel_gravity_torque(p: SwivelCarParams, theta2: float) -> float:
    """
    Swivel torque that holds the lifted body still: ``m g l cos(theta1 + phi/2) theta1'``.

    Odd in ``theta2`` (the potential has a V-shaped minimum at ``theta2 = 0``). # [N m]
    """
    theta1 = kinematics.lift_angle(p, theta2)
    return (p.mass * GRAVITY * p.l * np.cos(theta1 + p.phi / 2.0)
            * kinematics.lift_angle_derivative(p, theta2))


@dataclass(frozen=True)
class SwivelMoveResult:
    """Time series of a commanded swivel move (arrays of one length) and its summary."""

    time: np.ndarray  # [s]
    theta2: np.ndarray  # [rad]
    theta2_rate: np.ndarray  # [rad/s]
    torque: np.ndarray  # [N m] swivel motor torque
    energy: np.ndarray  # [J] cumulative int |tau theta2_dot| dt (no regeneration)
    work: np.ndarray  # [J] cumulative int tau theta2_dot dt (net mechanical work)
    peak_torque: float  # [N m] max |torque|
    total_energy: float  # [J] energy[-1]


def simulate_swivel_move(p: SwivelCarParams, theta2_target: float, theta2_start: float = 0.0,
                         duration: float = 15.0, samples: int = 1501,
                         stop_when_settled: bool = False,
                         max_rate: float = math.inf) -> SwivelMoveResult:
    """
    Simulate the swivel joint driven by the PID from rest towards a target.

    The joint starts at ``theta2_start``; the command steps to ``theta2_target`` (the thesis'
    move), or ramps there at ``max_rate`` (the controller's set-point rate limiter).

    The target and start must lie on the same side of zero (a move through zero switches the
    steering wheel; split it into two moves). Gains are ``p.kp, p.ki, p.kd``.

    Parameters
    ----------
    p : SwivelCarParams
        The car's model parameters.
    theta2_target, theta2_start : float
        Commanded and initial swivel angle. # [rad]
    duration : float
        Simulated time. # [s]
    samples : int
        Number of output samples (>= 2) over ``duration``.
    stop_when_settled : bool
        End early once ``|theta2 - target| < 1e-6 rad`` and ``|theta2_dot| < 1e-6 rad/s``.
    max_rate : float
        Rate limit of the PID's set point; ``inf`` steps it. # [rad/s]

    """
    target = _swivel(p, 'theta2_target', theta2_target)
    start = _swivel(p, 'theta2_start', theta2_start)
    duration = _positive('duration', duration)
    ramp = _positive('max_rate', max_rate) if max_rate != math.inf else math.inf
    if samples < 2:
        raise ValueError(f'samples must be >= 2, got {samples!r}')
    if target * start < 0.0:
        raise ValueError('theta2_start and theta2_target must not lie on both sides of zero')
    side = -1.0 if (target < 0.0 or start < 0.0) else 1.0
    profile = _lift_profile(p)
    d1, d2 = profile.derivative(1), profile.derivative(2)
    limit = p.max_swivel_angle
    weight = p.mass * GRAVITY * p.l
    front = front_swivel_inertia(p)

    def set_point(t: float) -> float:
        if ramp == math.inf:
            return target
        reach = ramp * t
        return start + min(reach, max(-reach, target - start))

    def torque_of(t: float, state: np.ndarray) -> float:
        theta2, rate, integral = state[0], state[1], state[2]
        return p.kp * (set_point(t) - theta2) + p.ki * integral - p.kd * rate

    def rhs(t: float, state: np.ndarray) -> list:
        theta2, rate = state[0], state[1]
        s = min(max(side * theta2, 0.0), limit)  # |theta2| on this move's side
        slope, curvature = float(d1(s)), float(d2(s))
        inertia = p.inertia * slope * slope + front
        gravity = side * weight * math.cos(float(profile(s)) + p.phi / 2.0) * slope
        torque = torque_of(t, state)
        error = set_point(t) - theta2
        if s == 0.0 and side * (torque - gravity) <= 0.0 and side * rate <= 0.0:
            # At theta2 = 0 the potential has a corner: the joint stays put until the motor
            # torque exceeds the holding torque (the body rests on both front wheels).
            return [0.0, -rate / _HOLD_TIME, error, 0.0, 0.0]
        # 1/2 J' rate^2 with J' = 2 I_s theta1' theta1'' d|theta2|/d theta2
        accel = (torque - gravity - side * p.inertia * slope * curvature * rate * rate) / inertia
        power = torque * rate
        return [rate, accel, error, abs(power), power]

    def settled(t: float, state: np.ndarray) -> float:
        if set_point(t) != target:
            return 1.0
        return max(abs(target - state[0]), abs(state[1])) - _SETTLED

    settled.terminal = True
    settled.direction = -1.0
    t_eval = np.linspace(0.0, duration, samples)
    sol = solve_ivp(rhs, (0.0, duration), [start, 0.0, 0.0, 0.0, 0.0], t_eval=t_eval,
                    method='LSODA', rtol=1e-8, atol=1e-10,
                    events=settled if stop_when_settled else None)
    if not sol.success:
        raise RuntimeError(f'swivel move integration failed: {sol.message}')
    torque = np.array([torque_of(t, sol.y[:, i]) for i, t in enumerate(sol.t)])
    return SwivelMoveResult(time=sol.t, theta2=sol.y[0], theta2_rate=sol.y[1], torque=torque,
                            energy=sol.y[3], work=sol.y[4],
                            peak_torque=float(np.max(np.abs(torque))),
                            total_energy=float(sol.y[3][-1]))


@functools.lru_cache(maxsize=256)
def _climb_cost(p: SwivelCarParams, step_height: float,
                max_rate: float) -> tuple[float, float]:
    theta2 = kinematics.swivel_for_step(p, step_height)
    if theta2 == 0.0:
        return 0.0, 0.0
    # long enough for the PID's integral to wind up to the holding torque of small steps
    move = simulate_swivel_move(p, theta2, duration=_CLIMB_DURATION, samples=6001,
                                stop_when_settled=True, max_rate=max_rate)
    # Part 3 (lifting the body onto the step with the lifted wheel on it) mirrors part 1: the
    # wheel on the step becomes the steering wheel of the same lift constraint.
    return move.peak_torque, 2.0 * move.total_energy


def climb_torque_energy(p: SwivelCarParams, step_height: float,
                        max_rate: float = math.inf) -> tuple[float, float]:
    """
    Predicted peak swivel torque and energy of climbing a step (thesis II.C.2, Fig. 31).

    Part 1 lifts the wheel: a PID move from 0 to ``kinematics.swivel_for_step``, over
    ``_CLIMB_DURATION`` (the PID's integral must first wind up to the holding torque); the
    thesis steps the command (``max_rate`` inf), the controller ramps its set point at
    ``max_rate`` [rad/s], which keeps the proportional term's kick off the peak.
    Part 3 lifts the body with the wheel resting on the step, modelled as the mirror of part 1
    (same lift constraint with the wheel on the step as the steering wheel), so the energy is
    twice part 1's and the peak the same. Driving (part 2) is not counted. Cached per
    ``(p, step_height, max_rate)``.

    Returns
    -------
    (peak_torque [N m], energy [J])

    Raises
    ------
    ValueError
        NaN, negative or out-of-reach step height.

    """
    return _climb_cost(p, _finite('step_height', step_height), float(max_rate))


# ----------------------------------------------------------------------------------------------
# 2. Car-like baseline: offset slider-crank (eqs. 101-110, Table 4)

@dataclass(frozen=True)
class CarLikeParams:
    """Thesis Table 4: a car-like robot lifting its front wheel onto a step."""

    mass: float = 21.0  # [kg] m_b
    inertia: float = 1.96  # [kg m^2] I_cm
    c_x: float = 0.215  # [m] centre of mass behind the front axle
    c_y: float = 0.25  # [m] centre of mass above the axle line
    body_length: float = 0.43  # [m] b, wheelbase
    wheel_radius: float = 0.075  # [m] R_w
    step_height: float = 0.016  # [m] Table 4 (the text and Figs. 60-61 say 12 mm)
    kp: float = 7.6  # [N m/rad]
    goal: float = math.pi / 2  # [rad] crank angle with the wheel centre above the edge

    def __post_init__(self) -> None:
        for name in ('mass', 'inertia', 'c_x', 'c_y', 'body_length', 'wheel_radius',
                     'step_height', 'kp', 'goal'):
            value = getattr(self, name)
            if not math.isfinite(value) or value <= 0.0:
                raise ValueError(f'{name} must be finite and > 0, got {value!r}')
        if self.step_height >= self.wheel_radius:
            raise ValueError(f'step_height must be below wheel_radius, got {self.step_height!r}')


@dataclass(frozen=True)
class CrankClimbResult:
    time: np.ndarray  # [s]
    crank_angle: np.ndarray  # [rad] theta_w
    torque: np.ndarray  # [N m] tau_w
    energy: np.ndarray  # [J] cumulative int tau_w theta_w_dot dt (eq. 110)
    peak_torque: float  # [N m]
    total_energy: float  # [J]
    final_crank_angle: float  # [rad]


def _crank_geometry(c: CarLikeParams, theta_w: np.ndarray):
    """
    Return the body pitch, the centre of mass' height above the edge and their derivatives.

    Body pitch alpha_b (eq. 108), the centre of mass' height above the step edge, and the
    derivatives of alpha_b, x and y with respect to the crank angle.
    """
    alpha = np.arcsin((c.wheel_radius * np.sin(theta_w) - c.wheel_radius + c.step_height)
                      / c.body_length)
    d_alpha = c.wheel_radius * np.cos(theta_w) / (c.body_length * np.cos(alpha))
    y = c.wheel_radius * np.sin(theta_w) - c.c_x * np.sin(alpha) + c.c_y * np.cos(alpha)
    dx = -c.wheel_radius * np.sin(theta_w) + (c.c_x * np.sin(alpha) - c.c_y * np.cos(alpha)) \
        * d_alpha
    dy = c.wheel_radius * np.cos(theta_w) - (c.c_x * np.cos(alpha) + c.c_y * np.sin(alpha)) \
        * d_alpha
    return alpha, y, d_alpha, dx, dy


@functools.lru_cache(maxsize=8)
def _crank_profile(c: CarLikeParams) -> tuple[float, CubicSpline]:
    """
    Start angle and a spline of (M, dV/dtheta_w) over the crank angle; M' by its derivative.

    ``M = m (x'^2 + y'^2) + I_cm alpha'^2`` (eq. 105 with eqs. 103-104), ``V' = m g y'``.
    """
    start = math.asin((c.wheel_radius - c.step_height) / c.wheel_radius)
    # the body pitch stays defined while R_w sin(theta_w) - R_w + h_step <= b
    stop = math.pi - start
    theta_w = np.linspace(start, stop, 4001)
    _, _, d_alpha, dx, dy = _crank_geometry(c, theta_w)
    inertia = c.mass * (dx * dx + dy * dy) + c.inertia * d_alpha * d_alpha
    return start, CubicSpline(theta_w, np.stack([inertia, c.mass * GRAVITY * dy], axis=-1))


def simulate_car_like_climb(c: CarLikeParams = CarLikeParams(), duration: float = 10.0,
                            samples: int = 1001) -> CrankClimbResult:
    """
    Simulate the car-like robot lifting its front wheel over the step edge (P controller).

    Starts at rest with the wheel touching both the ground and the edge,
    ``sin theta_w0 = (R_w - h_step) / R_w``; the climb is over when the crank reaches the goal
    (wheel centre above the edge), else at ``duration``. Energy is eq. 110,
    ``int tau_w theta_w_dot dt``.
    """
    duration = _positive('duration', duration)
    start, profile = _crank_profile(c)
    d_profile = profile.derivative(1)
    upper = profile.x[-1]

    def rhs(_t: float, state: np.ndarray) -> list:
        theta_w, rate = min(state[0], upper), state[1]
        inertia, weight = profile(theta_w)
        d_inertia = d_profile(theta_w)[0]
        torque = c.kp * (c.goal - theta_w)
        accel = (torque - weight - 0.5 * d_inertia * rate * rate) / inertia
        return [rate, accel, torque * rate]

    def reached(_t: float, state: np.ndarray) -> float:
        return state[0] - c.goal

    reached.terminal = True
    reached.direction = 1.0
    t_eval = np.linspace(0.0, duration, samples)
    sol = solve_ivp(rhs, (0.0, duration), [start, 0.0, 0.0], t_eval=t_eval, method='LSODA',
                    rtol=1e-9, atol=1e-11, events=reached)
    if not sol.success:
        raise RuntimeError(f'crank integration failed: {sol.message}')
    torque = c.kp * (c.goal - sol.y[0])
    return CrankClimbResult(time=sol.t, crank_angle=sol.y[0], torque=torque, energy=sol.y[2],
                            peak_torque=float(np.max(np.abs(torque))),
                            total_energy=float(sol.y[2][-1]),
                            final_crank_angle=float(sol.y[0][-1]))


# ----------------------------------------------------------------------------------------------
# 3. Planar model with nonholonomic constraints (eqs. 29-44)

# Columns of the planar profile: contact a, b, steering delta, then the body points (x, y):
# apex projection, front right wheel centre, front left wheel centre.
_N_PROFILE = 9


@functools.lru_cache(maxsize=16)
def _planar_profile(p: SwivelCarParams) -> CubicSpline:
    theta2 = np.linspace(0.0, p.max_swivel_angle, _PROFILE_SIZE)
    state = kinematics.kinematic_state(p, theta2)
    frames = kinematics.forward_kinematics(p, theta2, state.theta1)
    apex_x = p.l * np.cos(state.theta1 + p.phi / 2.0)
    columns = [state.contact_x, state.contact_y, state.steering, apex_x, np.zeros_like(apex_x),
               frames.o3[:, 0, 3], frames.o3[:, 1, 3], frames.o3_left[:, 0, 3],
               frames.o3_left[:, 1, 3]]
    return CubicSpline(theta2, np.stack(columns, axis=-1))


# which profile columns are lateral (y-like, odd under theta2 -> -theta2)
_MIRROR = np.array([1.0, -1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0])


def _profile_at(p: SwivelCarParams, theta2: float, rate: float, side: float):
    """
    Profile values and their time derivatives at swivel angle theta2 moving at ``rate``.

    ``side`` (+1 / -1) says which side of zero the move lies on (which wheel steers). The
    spline's cubic pieces are evaluated directly: this runs once per DAE right-hand side.
    """
    spline = _planar_profile(p)
    s = min(max(side * theta2, 0.0), p.max_swivel_angle)
    i = min(max(int(np.searchsorted(spline.x, s)) - 1, 0), len(spline.x) - 2)
    dx = s - spline.x[i]
    c0, c1, c2, c3 = spline.c[:, i, :]
    mirror = _MIRROR if side < 0.0 else 1.0
    value = mirror * (((c0 * dx + c1) * dx + c2) * dx + c3)
    d1 = mirror * side * ((3.0 * c0 * dx + 2.0 * c1) * dx + c2)
    d2 = mirror * (6.0 * c0 * dx + 2.0 * c1)
    return value, d1 * rate, d2 * rate * rate


def _rot(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s], [s, c]])


def _perp(v: np.ndarray) -> np.ndarray:
    """Rotate vectors (..., 2) by +90 deg."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


@dataclass(frozen=True)
class _PlanarModel:
    masses: np.ndarray  # [kg] (5,) body, rear right, rear left, front right, front left wheel
    yaw_inertia: float  # [kg m^2] of the body about its own mass point

    @staticmethod
    def of(p: SwivelCarParams, yaw_inertia: float | None) -> '_PlanarModel':
        body = p.mass - 4.0 * p.wheel_mass
        if yaw_inertia is None:
            # uniform plate of the car's footprint (the thesis gives no I_car)
            yaw_inertia = body * (p.wheelbase ** 2 + (2.0 * p.h) ** 2) / 12.0
        return _PlanarModel(np.array([body] + [p.wheel_mass] * 4), float(yaw_inertia))


def _points(p: SwivelCarParams, value, d1, d2):
    """Body-frame mass points (5, 2) and their time derivatives."""
    rear = np.array([[0.0, -p.h], [0.0, p.h]])
    pts = np.vstack([value[3:5], rear, value[5:7], value[7:9]])
    dpts = np.vstack([d1[3:5], np.zeros((2, 2)), d1[5:7], d1[7:9]])
    ddpts = np.vstack([d2[3:5], np.zeros((2, 2)), d2[5:7], d2[7:9]])
    return pts, dpts, ddpts


def _planar_system(p, model, q, qd, value, d1, d2):
    """Mass matrix, bias forces, constraint matrix and its velocity/acceleration terms."""
    yaw, wz = q[2], qd[2]
    rot = _rot(yaw)
    pts, dpts, ddpts = _points(p, value, d1, d2)
    r, rd, rdd = pts @ rot.T, dpts @ rot.T, ddpts @ rot.T
    jr = _perp(r)
    m = model.masses
    extra = -wz * wz * r + 2.0 * wz * _perp(rd) + rdd
    mass_matrix = np.empty((3, 3))
    total = float(np.sum(m))
    first = m @ jr  # sum of m_i * J R s_i
    mass_matrix[:2, :2] = np.diag([total, total])
    mass_matrix[:2, 2] = mass_matrix[2, :2] = first
    mass_matrix[2, 2] = float(np.sum(m * np.sum(jr * jr, axis=1)))
    force = m @ extra
    bias = np.array([force[0], force[1], float(np.sum(m * np.sum(jr * extra, axis=1)))])
    mass_matrix[2, 2] += model.yaw_inertia
    # rear axle: no lateral velocity of the axle middle
    n_rear = np.array([-math.sin(yaw), math.cos(yaw)])
    # steering wheel contact: no velocity across its rolling direction
    psi = yaw + value[2]
    n_front = np.array([-math.sin(psi), math.cos(psi)])
    contact = rot @ value[0:2]
    contact_d = rot @ d1[0:2]
    contact_dd = rot @ d2[0:2]
    jc = _perp(contact)
    a_matrix = np.array([[n_rear[0], n_rear[1], 0.0],
                         [n_front[0], n_front[1], n_front @ jc]])
    a_zero = np.array([0.0, n_front @ contact_d])
    # d/dt of the constraint rows applied to qd, plus the prescribed terms
    n_rear_d = -wz * np.array([math.cos(yaw), math.sin(yaw)])
    n_front_d = -(wz + d1[2]) * np.array([math.cos(psi), math.sin(psi)])
    w_contact = qd[:2] + wz * jc + contact_d
    accel_bias = np.array([
        n_rear_d @ qd[:2],
        n_front_d @ w_contact + n_front @ (-wz * wz * contact + 2.0 * wz * _perp(contact_d)
                                           + contact_dd)])
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
    rot = _rot(q[2])
    pts, dpts, _ = _points(p, value, d1, d1 * 0.0)
    vel = qd[:2] + qd[2] * _perp(pts @ rot.T) + dpts @ rot.T
    return 0.5 * float(np.sum(model.masses * np.sum(vel * vel, axis=1))) \
        + 0.5 * model.yaw_inertia * qd[2] ** 2


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
    start = _swivel(p, 'theta2_from', theta2_from)
    end = _swivel(p, 'theta2_to', theta2_to)
    rate = _positive('rate', rate)
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
    theta2 = _swivel(p, 'theta2', theta2)
    duration = _positive('duration', duration)
    qd0 = np.array([_finite('velocity', v) for v in velocity])
    return _simulate_planar(p, theta2, 0.0, duration, qd0, samples, yaw_inertia, rtol)


@functools.lru_cache(maxsize=16)
def _drift_from_zero(p: SwivelCarParams) -> CubicSpline:
    """
    Return the pose after a move from rest at 0 to theta2 >= 0, for every theta2 at once.

    The run 0 -> max_swivel_angle passes through each of them.
    """
    # rtol 1e-8: within 1e-7 m and rad of the default 1e-9, in a fifth of its time (1 s).
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
    range (a spline; ~1e-7 accurate); others are integrated once and cached per arguments
    (rounded to 1e-6 rad).

    Returns
    -------
    (dx [m], dy [m], dyaw [rad])
        In the base_link frame at the start of the move.

    """
    a = round(_swivel(p, 'theta2_from', theta2_from), 6)
    b = round(_swivel(p, 'theta2_to', theta2_to), 6)
    if a == b:
        return 0.0, 0.0, 0.0
    return _drift(p, a, b)
