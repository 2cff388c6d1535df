"""
Car-like baseline: a car-like robot lifting its front wheel onto a step (thesis IV.A).

The climb as an offset slider-crank (eqs. 101-110, Table 4), solved as printed (eqs. 103-106
are consistent with the centre of mass at
``(R_w cos theta_w - c_x cos a - c_y sin a, R_w sin theta_w - c_x sin a + c_y cos a)``
relative to the step edge), with a P controller on the crank angle (eq. 109).
"""

from __future__ import annotations

from dataclasses import dataclass
import functools
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

from swivel_car_model.dynamics._common import GRAVITY, positive


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
    duration = positive('duration', duration)
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
