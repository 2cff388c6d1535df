"""
PID on the swivel angle (thesis eq. 26, corrected).

Thesis eq. 26 reads ``tau = Kp (theta_2d - theta_2) + K_D theta_2_dot + K_I int(e)``: with
positive K_D the ``+K_D theta_2_dot`` term pushes the joint further in the direction it already
moves, i.e. it *un*-damps. The derivative term here is ``-K_D theta_2_dot``: derivative on the
measurement (not on the error), so a set-point step gives no torque kick.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from swivel_car_model.checks import check_number


@dataclass(frozen=True)
class PidConfig:
    """
    Gains and limits of the swivel PID.

    Parameters
    ----------
    kp : float
        Proportional gain, >= 0. # [N m/rad]
    ki : float
        Integral gain, >= 0. # [N m/(rad s)]
    kd : float
        Derivative gain (on the measured rate), >= 0. # [N m s/rad]
    max_torque : float
        Output clamp, > 0. # [N m]
    max_integral_torque : float
        Clamp on the integral contribution, >= 0. # [N m]
    integral_band : float
        While the set point moves, the integral only integrates while |error| is below this,
        > 0 (inf: always): during large moves (the set point ramping away) it would only wind
        up. Once the set point rests it always integrates: a gravity load larger than
        kp * integral_band must not leave the swivel short of its target. # [rad]

    """

    kp: float
    ki: float
    kd: float
    max_torque: float
    max_integral_torque: float
    integral_band: float = math.inf

    def __post_init__(self) -> None:
        for name in ('kp', 'ki', 'kd', 'max_integral_torque'):
            check_number(name, getattr(self, name), at_least=0.0)
        check_number('max_torque', self.max_torque, above=0.0)
        check_number('integral_band', self.integral_band, above=0.0, allow_inf=True)


@dataclass(frozen=True)
class PidOutput:
    """One PID step's result, all in [N m] but ``saturated``."""

    torque: float
    p_term: float
    i_term: float
    d_term: float
    saturated: bool


class SwivelPid:
    """
    PID with derivative on measurement, output clamp and conditional-integration anti-windup.

    The integral only grows while the set point rests or the error is inside
    ``integral_band``, and while the clamped output is not pushing against its limit in the
    direction the error asks for; it is itself clamped to ``max_integral_torque``.
    """

    def __init__(self, config: PidConfig) -> None:
        self.config = config
        self._integral = 0.0  # [N m], the integral term itself (ki already applied)

    def reset(self) -> None:
        """Forget the integral."""
        self._integral = 0.0

    def step(self, set_point: float, measured: float, measured_rate: float,
             dt: float, set_point_moving: bool = False) -> PidOutput:
        """
        Torque for one control period.

        Parameters
        ----------
        set_point, measured : float
            Wanted and measured swivel angle. # [rad]
        measured_rate : float
            Measured swivel rate. # [rad/s]
        dt : float
            Time since the previous step, >= 0 (0: no integration). # [s]
        set_point_moving : bool
            The set point is still on its way (a rate limiter ramping it).

        """
        for name, value in (('set_point', set_point), ('measured', measured),
                            ('measured_rate', measured_rate), ('dt', dt)):
            if not math.isfinite(value):
                raise ValueError(f'{name} must be finite, got {value!r}')
        if dt < 0.0:
            raise ValueError(f'dt must be >= 0, got {dt!r}')
        c = self.config
        error = set_point - measured
        p_term = c.kp * error
        d_term = -c.kd * measured_rate
        integrating = not set_point_moving or abs(error) < c.integral_band
        candidate = _clamp(self._integral + c.ki * error * dt * integrating,
                           c.max_integral_torque)
        unclamped = p_term + candidate + d_term
        saturated = abs(unclamped) > c.max_torque
        if not (saturated and error * unclamped > 0.0):
            self._integral = candidate
        total = p_term + self._integral + d_term
        torque = _clamp(total, c.max_torque)
        return PidOutput(torque, p_term, self._integral, d_term, abs(total) > c.max_torque)


def _clamp(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))
