"""
Swivel move of the swivel car: torque and energy of the steering mechanism (thesis II.C).

Steering mechanism with PID (eqs. 17-26). The whole mass sits at the apex ``C_m`` and pitches
with the lift angle about the rear axle, ``theta1 = theta1(theta2)`` (the lift constraint), so
with the swivel angle as the only coordinate::

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
"""

from __future__ import annotations

from dataclasses import dataclass
import functools
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

from swivel_car_model import kinematics
from swivel_car_model.dynamics._common import (finite, GRAVITY, positive, PROFILE_SIZE,
                                               swivel_angle)
from swivel_car_model.params import SwivelCarParams

_CLIMB_DURATION = 300.0  # [s]
_SETTLED = 1e-6  # [rad], [rad/s]
_HOLD_TIME = 1e-3  # [s] time constant that bleeds off a residual rate while the joint is held


@functools.lru_cache(maxsize=16)
def _lift_profile(p: SwivelCarParams) -> CubicSpline:
    """Spline of theta1(|theta2|) with exact first derivatives (Hermite) on [0, max]."""
    theta2 = np.linspace(0.0, p.max_swivel_angle, PROFILE_SIZE)
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
    target = swivel_angle(p, 'theta2_target', theta2_target)
    start = swivel_angle(p, 'theta2_start', theta2_start)
    duration = positive('duration', duration)
    ramp = positive('max_rate', max_rate) if max_rate != math.inf else math.inf
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
    return _climb_cost(p, finite('step_height', step_height), float(max_rate))
