"""
The swivel car controller: command arbitration, limits, deadman, tip-over guard and PID.

One ``step`` per measured joint state gives one actuator command (swivel torque, drive speed);
``set_cmd_vel`` and ``set_swivel_command`` take the operator's and the planner's commands and
raise ``ValueError`` (changing nothing) for commands they refuse.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
import math
from typing import ClassVar

from swivel_car_control.core.limits import SlewLimiter, steering_speed_scale
from swivel_car_control.core.pid import PidConfig, PidOutput, SwivelPid
from swivel_car_control.core.steering import (
    SteeringMap, swivel_is_tip_safe, tip_safe_swivel_limit)
from swivel_car_model import planar
from swivel_car_model.checks import check_number
from swivel_car_model.description import described
from swivel_car_model.params import SwivelCarParams

SOURCE_CMD_VEL = 'cmd_vel'
SOURCE_SWIVEL_COMMAND = 'swivel_command'
SOURCE_HOLD = 'hold'


@dataclass(frozen=True)
class ControllerConfig:
    """
    Limits and behaviour of the controller (the PID gains live in ``SwivelCarParams``).

    Each field's metadata ``description`` (with its unit) is also its ROS parameter's.
    """

    max_torque: float = described(
        30.0, 'swivel torque clamp; the node sets it to the swivel_torque_limit [N m]')
    max_integral_torque: float = described(15.0, 'clamp on the PID integral contribution [N m]')
    integral_band: float = described(
        0.05, 'while the set point ramps, the PID integrates only while |error| is below this '
        '[rad]')
    max_swivel_rate: float = described(1.5, 'swivel set-point rate limit [rad/s]')
    max_linear_velocity: float = described(0.5, 'forward speed limit of base_link [m/s]')
    max_linear_acceleration: float = described(1.0, 'forward acceleration limit [m/s^2]')
    max_angular_velocity: float = described(2.0, 'yaw rate limit [rad/s]')
    max_angular_acceleration: float = described(4.0, 'yaw acceleration limit [rad/s^2]')
    cmd_vel_timeout: float = described(
        0.5, 'deadman: older cmd_vel stops the drive, holds the swivel; 0 disables [s]')
    swivel_command_timeout: float = described(
        0.5, 'deadman: a held swivel_command not renewed for this long (node clock, from '
        'receipt) is released: drive stops, swivel holds, cmd_vel steers again; 0 disables [s]')
    slowdown_start: float = described(
        0.15, 'swivel error below which the drive runs at full speed [rad]')
    slowdown_stop: float = described(
        0.6, 'swivel error above which the drive stops; cos(error) between [rad]')
    tip_over_margin: float = described(
        0.1, 'margin on thesis eq. 72, (pi - phi)/2 - theta1 >= margin [rad]')
    # The fields ``SwivelController.step`` reads afresh every period: they may change while
    # it runs (``reconfigure``).
    LIVE: ClassVar[tuple[str, ...]] = ('cmd_vel_timeout', 'swivel_command_timeout',
                                       'slowdown_start', 'slowdown_stop')

    def __post_init__(self) -> None:
        positive = ('max_torque', 'integral_band', 'max_swivel_rate', 'max_linear_velocity',
                    'max_linear_acceleration', 'max_angular_velocity',
                    'max_angular_acceleration')
        for field in fields(self):
            bound = {'above': 0.0} if field.name in positive else {'at_least': 0.0}
            check_number(field.name, getattr(self, field.name), **bound)
        if not self.slowdown_start <= self.slowdown_stop <= math.pi / 2:
            raise ValueError(
                'need 0 <= slowdown_start <= slowdown_stop <= pi/2, got '
                f'{self.slowdown_start!r}, {self.slowdown_stop!r}')


@dataclass(frozen=True)
class SwivelCommandRequest:
    """The planner's direct command, as accepted."""

    angle: float  # [rad]
    max_rate: float  # [rad/s], 0 = controller default
    drive_speed: float  # [rad/s] at the wheels
    stamp: float  # [s] when it was received, for the deadman
    free: bool = False  # no swivel torque within the tip-safe limit


@dataclass(frozen=True)
class ControlOutput:
    """One control period's command and the state behind it."""

    swivel_torque: float  # [N m]
    drive_speed: float  # [rad/s] at the wheels
    set_point: float  # [rad] after the rate limiter
    target: float  # [rad] before the rate limiter
    pid: PidOutput
    source: str  # SOURCE_*
    v_out: float  # [m/s] commanded forward speed
    omega_out: float  # [rad/s] yaw rate the car will have at this speed once steered
    cmd_vel_timed_out: bool
    swivel_command_timed_out: bool


class SwivelController:
    """
    Controller core; see the module docstring.

    Parameters
    ----------
    p : SwivelCarParams
        Geometry, the PID gains ``kp, ki, kd`` and the ``swivel_limit``.
    config : ControllerConfig

    Raises
    ------
    ValueError
        The tip-over rule unsatisfiable.

    """

    def __init__(self, p: SwivelCarParams, config: ControllerConfig) -> None:
        self.p = p
        self.config = config
        self.swivel_limit = tip_safe_swivel_limit(p, p.swivel_limit,
                                                  config.tip_over_margin)  # [rad]
        self.steering = SteeringMap(p, self.swivel_limit, config.max_linear_velocity)
        self._model = self.steering.model
        self.pid = SwivelPid(PidConfig(p.kp, p.ki, p.kd, config.max_torque,
                                       config.max_integral_torque, config.integral_band))
        self._v = SlewLimiter(config.max_linear_velocity, config.max_linear_acceleration)
        self._omega = SlewLimiter(config.max_angular_velocity, config.max_angular_acceleration)
        self._drive = SlewLimiter(config.max_linear_velocity / p.r,
                                  config.max_linear_acceleration / p.r)
        self._set_point = SlewLimiter(self.swivel_limit, config.max_swivel_rate)
        self._target: float | None = None  # [rad]; None until the first measurement
        self._last_time: float | None = None  # [s]
        self._cmd_vel: tuple[float, float, float] | None = None  # (v, omega, stamp)
        self._swivel_command: SwivelCommandRequest | None = None
        self._restart_at: float | None = None  # [s] time of a world reset not yet stepped

    @property
    def swivel_command(self) -> SwivelCommandRequest | None:
        """Return the planner's command being held, if any."""
        return self._swivel_command

    def reconfigure(self, config: ControllerConfig) -> None:
        """
        Go on with ``config``, which may differ from the current one only in its live fields.

        Those are ``ControllerConfig.LIVE``.

        Raises
        ------
        ValueError
            Another field differs; nothing changes.

        """
        fixed = [f.name for f in fields(config) if f.name not in config.LIVE
                 and getattr(config, f.name) != getattr(self.config, f.name)]
        if fixed:
            raise ValueError(f'{", ".join(fixed)} cannot change while the controller runs')
        self.config = config

    def reset(self, t: float) -> None:
        """
        Start afresh after a reset of the world at time ``t`` [s].

        The sim's ``~/reset`` put the car back at rest, swivel 0: the commands given so far
        are dropped now, and the first step at ``t`` or later starts afresh from the swivel
        measured then, held with the drive stopped until a new command comes. Steps of
        earlier times (states from before the reset, still on their way) go on as before.

        Raises
        ------
        ValueError
            ``t`` is not finite; nothing changes.

        """
        if not math.isfinite(t):
            raise ValueError(f'reset time must be finite, got {t!r}')
        self._cmd_vel = self._swivel_command = None
        self._restart_at = float(t)

    def set_cmd_vel(self, v: float, omega: float, stamp: float) -> None:
        """
        Take a velocity command: v [m/s], omega [rad/s], stamp [s] (its time).

        Raises
        ------
        ValueError
            A field is not finite; the last command stays.

        """
        for name, value in (('linear.x', v), ('angular.z', omega), ('stamp', stamp)):
            if not math.isfinite(value):
                raise ValueError(f'cmd_vel {name} is {value!r}: rejected, keeping the last '
                                 'safe command')
        self._cmd_vel = (float(v), float(omega), float(stamp))

    def set_swivel_command(self, angle: float, max_rate: float, drive_speed: float,
                           hold: bool, stamp: float, free: bool = False) -> None:
        """
        Take the planner's direct command, received at ``stamp`` [s] (the deadman's reference).

        ``hold=False`` releases it to cmd_vel. ``free`` lets the swivel turn with no torque
        (``angle`` unused) while it stays within the tip-safe limit, where it is held.

        Raises
        ------
        ValueError
            Non-finite field, angle beyond the swivel limit, negative rate, or an angle that
            breaks the tip-over rule with the margin; the previous command stays.

        """
        if not hold:
            self._swivel_command = None
            return
        for name, value in (('angle', angle), ('max_rate', max_rate),
                            ('drive_speed', drive_speed), ('stamp', stamp)):
            if not math.isfinite(value):
                raise ValueError(f'swivel_command {name} is {value!r}: refused')
        if max_rate < 0.0:
            raise ValueError(f'swivel_command max_rate must be >= 0, got {max_rate!r}: refused')
        limit = self.p.swivel_limit
        if abs(angle) > limit:
            raise ValueError(f'swivel_command angle {angle!r} rad is outside +-{limit!r} rad: '
                             'refused')
        # Beyond the tip-safe limit the way there crosses unsafe angles even where the target
        # itself would be safe (the lift angle peaks inside the swivel range).
        if abs(angle) > self.swivel_limit or not swivel_is_tip_safe(
                self._model, angle, self.config.tip_over_margin):
            raise ValueError(
                f'swivel_command angle {angle!r} rad breaks the tip-over rule (thesis eq. 72) '
                f'with margin {self.config.tip_over_margin!r} rad: refused')
        self._swivel_command = SwivelCommandRequest(float(angle), float(max_rate),
                                                    float(drive_speed), float(stamp),
                                                    bool(free))

    def step(self, t: float, measured: float, measured_rate: float) -> ControlOutput:
        """
        Run one control period at time ``t`` [s] with the measured swivel angle and rate.

        The angle is in [rad], the rate in [rad/s]. Time going backwards (a restarted sim)
        restarts the controller's memory and drops the commands given before: they belong to
        the old run. So does the first step at or after a ``reset`` time, keeping the commands
        given since the reset.

        The deadmans count in the time of these steps, whatever clock stamped a command: a
        command stamped later than ``t`` (another clock, a /clock far ahead, a runtime
        ``use_sim_time`` change) counts as given at ``t``, so no stamp keeps it alive
        longer than its timeout of steps.
        """
        for name, value in (('t', t), ('measured', measured), ('measured_rate', measured_rate)):
            if not math.isfinite(value):
                raise ValueError(f'{name} must be finite, got {value!r}')
        went_back = self._last_time is not None and t < self._last_time
        if went_back:
            self._cmd_vel = self._swivel_command = None
        reset = self._restart_at is not None and (went_back or t >= self._restart_at)
        if reset:
            self._restart_at = None
        if self._last_time is None or went_back or reset:
            self._restart(measured)
            dt = 0.0
        else:
            dt = t - self._last_time
        self._last_time = t
        if self._cmd_vel is not None and self._cmd_vel[2] > t:
            self._cmd_vel = (*self._cmd_vel[:2], t)
        if self._swivel_command is not None and self._swivel_command.stamp > t:
            self._swivel_command = replace(self._swivel_command, stamp=t)
        timed_out = False
        max_rate = None
        command = self._swivel_command
        command_timed_out = command is not None and 0.0 < self.config.swivel_command_timeout \
            < t - command.stamp
        if command_timed_out:
            self._swivel_command = command = None
        free = command is not None and command.free and abs(measured) < self.swivel_limit
        if command is not None and command.free:
            # Bumpless: the set point rides on the measured angle (the limiter clamps it to
            # the tip-safe limit, where it is held), so holding again starts from there.
            self._set_point.reset(measured)
            if free:
                self.pid.reset()
        if command is not None:
            source = SOURCE_SWIVEL_COMMAND
            self._target = self._set_point.value if command.free else command.angle
            if command.max_rate > 0.0:
                max_rate = command.max_rate
            drive_target = command.drive_speed
            # The rate limiters follow along, so a release continues smoothly.
            self._v.step(drive_target * self.p.r, dt)
            self._omega.step(0.0, dt)
        else:
            v, omega = 0.0, 0.0
            if self._cmd_vel is not None:
                timeout = self.config.cmd_vel_timeout
                timed_out = timeout > 0.0 and t - self._cmd_vel[2] > timeout
                if not timed_out:
                    v, omega = self._cmd_vel[0], self._cmd_vel[1]
            resolved = self.steering.resolve(self._v.step(v, dt), self._omega.step(omega, dt))
            if v == 0.0 and omega == 0.0:
                # Stopping (asked, or deadman): the swivel holds; only the drive ramps down,
                # so the car keeps its arc instead of steering as v and omega decay unequally.
                source = SOURCE_HOLD
                drive_target = 0.0
            else:
                source = SOURCE_CMD_VEL
                if resolved.swivel is not None:  # None while both ramps still sit at zero
                    self._target = resolved.swivel
                speed = (self._tightest_turn_speed(resolved.omega, measured)
                         if resolved.tightest else resolved.v)
                drive_target = planar.wheel_rate_for_speed(self.p, speed)
        set_point = self._set_point.step(self._target, dt, max_rate)
        pid = (PidOutput(0.0, 0.0, 0.0, 0.0, False) if free
               else self.pid.step(set_point, measured, measured_rate, dt,
                                  set_point_moving=set_point != self._target))
        scale = steering_speed_scale(self._target - measured, self.config.slowdown_start,
                                     self.config.slowdown_stop)
        drive = self._drive.step(drive_target * scale, dt)
        v_out = drive * self.p.r
        omega_out = self._model.curvature(self._target) * v_out
        return ControlOutput(pid.torque, drive, set_point, self._target, pid, source, v_out,
                             omega_out, timed_out, command_timed_out)

    def _tightest_turn_speed(self, omega: float, measured: float) -> float:
        """
        Forward speed [m/s] giving the yaw rate ``omega`` [rad/s] at the *measured* swivel.

        Near the swivel limit the curvature is steep in theta2 (4.2 1/m at 1.40 rad, 4.5 at
        1.41 with the default geometry), so the few hundredths of a radian the swivel sits off
        its set point under load would change the yaw rate by several per cent; at the limit
        the speed only serves the yaw rate, so it follows the measured curvature.
        """
        limit = self.p.max_swivel_angle
        curvature = self._model.curvature(max(-limit, min(limit, measured)))
        if curvature * omega <= 0.0 or abs(curvature) < 0.5 * self.steering.max_curvature:
            return 0.0  # still steering towards the turn: the speed scale holds the drive
        return max(-self.config.max_linear_velocity,
                   min(self.config.max_linear_velocity, omega / curvature))

    def _restart(self, measured: float) -> None:
        hold = max(-self.swivel_limit, min(self.swivel_limit, measured))
        self.pid.reset()
        self._set_point.reset(hold)
        self._target = hold
        for limiter in (self._v, self._omega, self._drive):
            limiter.reset(0.0)
