"""
What the controller and odometry nodes do with one ``joint_states`` message, ROS-free.

The nodes call these on the message's fields (stamp in seconds, names, positions,
velocities); the in-process stack (``swivel_car_studies.inprocess``) calls them on the sim
core's state, so both run the same code on the same floats.
"""

from __future__ import annotations

import math
from typing import Sequence

from swivel_car_control.core.controller import ControlOutput, SwivelController
from swivel_car_control.joints import JointReader, JointSample, MissingJointError
from swivel_car_model.checks import check_number
from swivel_car_model.params import SwivelCarParams
from swivel_car_model.planar import OffsetTricycleOdometry

# 'swivel': the offset tricycle's steering constraint (thesis II.E); 'rear_wheels': the yaw
# rate from the rear wheels' rate difference (the speed from the model in both cases).
YAW_RATE_SOURCES = ('swivel', 'rear_wheels')
# A swivel reading this far past the joint limit (compliance, sensor noise) is clamped to it;
# further past it, it is a bad reading (the joint has a hard stop there).
LIMIT_SLACK = 0.05  # [rad]
# A swivel turning faster than this is a bad reading. The fastest the joint really turns: the
# actuator's full torque (30 N m) from stop to stop, 65 rad/s at the second stop in the sim,
# standing or driving (test_swivel_rate_bound.py); a controller starved of CPU holds a
# saturated command that long. Twice that, so that only a reading no motion gives is refused.
MAX_SWIVEL_RATE = 130.0  # [rad/s]
# Longest gap between two joint_states taken as the same run; a sim at 10 Hz or more never
# leaves one this long, a fake stamp does.
MAX_GAP = 1.0  # [s]


class UnconfirmedStamp(MissingJointError):
    """The message's stamp jumped back, or ahead by more than ``MAX_GAP``: not yet trusted."""


class ImpossibleReading(MissingJointError):
    """A swivel reading the joint cannot give (a driver glitch): past its stop, or too fast."""


def check_swivel_reading(name: str, names: Sequence[str], positions: Sequence[float],
                         velocities: Sequence[float], limit: float) -> None:
    """
    Refuse a reading of joint ``name`` the swivel cannot physically give.

    Positions [rad] and velocities [rad/s] are in the order of ``names``; ``limit`` is the
    joint's mechanical limit [rad]. A joint or value not reported, or a non-finite position,
    is left to ``JointReader``.

    Raises
    ------
    ImpossibleReading
        Naming the joint and the value.

    """
    if name not in names:
        return
    i = list(names).index(name)
    position = positions[i] if i < len(positions) else math.nan  # [rad]
    rate = velocities[i] if i < len(velocities) else math.nan  # [rad/s]
    if math.isfinite(position) and abs(position) > limit + LIMIT_SLACK:
        raise ImpossibleReading(f'joint {name!r} position {position!r} rad is beyond its '
                                f'stop at {limit:.3f} rad (a driver glitch?): refused')
    if abs(rate) > MAX_SWIVEL_RATE:
        raise ImpossibleReading(f'joint {name!r} velocity {rate!r} rad/s is beyond '
                                f'{MAX_SWIVEL_RATE:g} rad/s (a driver glitch?): refused')


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """Rotation about z by ``yaw`` [rad] as a quaternion (x, y, z, w) [1]."""
    return 0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw)


class JointStateController:
    """
    The controller's answer to one ``joint_states``.

    The swivel joint read by name (its rate differenced from positions when not reported),
    then one ``SwivelController.step``. A stamp that jumps back or more than ``MAX_GAP``
    ahead is trusted once the next message follows it (a restarted sim starts again at 0);
    until then nothing is stepped, so one faulty message drops no command and moves no
    limiter (issue 12: a single stamp of 0 s while driving dropped the cmd_vel in force).

    Parameters
    ----------
    core : SwivelController
    swivel_joint : str
        Name of the swivel (or steering) joint in the message.

    """

    def __init__(self, core: SwivelController, swivel_joint: str) -> None:
        self.core = core
        self.swivel_joint = swivel_joint
        self._joints = JointReader([swivel_joint])
        self.last_time: float | None = None  # [s] stamp of the last message answered
        self._reset_at: float | None = None  # [s] time of a world reset not yet answered
        self._jumped_to: float | None = None  # [s] stamp of an unconfirmed jump

    def reset(self, t: float) -> None:
        """
        Start afresh after a reset of the world at time ``t`` [s].

        As ``SwivelController.reset``; also, the positions read before it are not differenced
        against the states from ``t`` on.

        Raises
        ------
        ValueError
            ``t`` is not finite; nothing changes.

        """
        self.core.reset(t)
        self._reset_at = t

    def answer(self, t: float, names: Sequence[str], positions: Sequence[float],
               velocities: Sequence[float]) -> tuple[JointSample, ControlOutput]:
        """
        Return the swivel sample and the control output for the state of time ``t`` [s].

        Positions [rad] and velocities [rad/s] are in the order of ``names``. Time going back
        (a restarted sim) or reaching a ``reset`` time forgets the previous positions.

        Raises
        ------
        swivel_car_control.joints.MissingJointError
            No usable swivel reading, an ``ImpossibleReading`` or an ``UnconfirmedStamp``;
            nothing was stepped and nothing remembered (answer with zero torque and drive).

        """
        last = self.last_time
        jumped_to, self._jumped_to = self._jumped_to, None  # only the next message confirms
        if last is not None and not last <= t <= last + MAX_GAP and not (
                jumped_to is not None and jumped_to < t <= jumped_to + MAX_GAP):
            self._jumped_to = t
            direction = 'before' if t < last else 'after'
            raise UnconfirmedStamp(
                f'joint_states stamp {t:.3f} s is {abs(t - last):.3f} s {direction} the last one '
                f'({last:.3f} s): not acted on until the next message confirms the jump')
        name = self.swivel_joint
        check_swivel_reading(name, names, positions, velocities, self.core.p.max_swivel_angle)
        if (self.last_time is not None and t < self.last_time) or (
                self._reset_at is not None and t >= self._reset_at):
            self._joints.reset()
            self._reset_at = None
        swivel = self._joints.read(t, names, positions, velocities)[name]
        self.last_time = t
        return swivel, self.core.step(t, swivel.position, swivel.rate)


class JointStateOdometry:
    """
    Offset-tricycle odometry (``OffsetTricycleOdometry``) fed from ``joint_states``.

    It also decides when to publish: by joint_states time, at most one message per state, so
    that in a lockstep sim every run publishes the same poses.

    Parameters
    ----------
    car : SwivelCarParams
    swivel_joint, rear_left_wheel_joint, rear_right_wheel_joint : str
        Joint names in the message.
    yaw_rate_source : str
        One of ``YAW_RATE_SOURCES``.
    publish_rate : float
        Odometry messages per second of joint_states time, > 0. # [Hz]

    """

    def __init__(self, car: SwivelCarParams, swivel_joint: str, rear_left_wheel_joint: str,
                 rear_right_wheel_joint: str, yaw_rate_source: str,
                 publish_rate: float) -> None:
        if yaw_rate_source not in YAW_RATE_SOURCES:
            raise ValueError(f'yaw_rate_source must be one of {YAW_RATE_SOURCES}, got '
                             f'{yaw_rate_source!r}')
        check_number('publish_rate', publish_rate, above=0.0, unit='Hz')
        self.car = car
        self.odometry = OffsetTricycleOdometry(car)
        self._names = (swivel_joint, rear_left_wheel_joint, rear_right_wheel_joint)
        self._rear_wheels_yaw = yaw_rate_source == 'rear_wheels'
        self._period = 1.0 / publish_rate  # [s]
        self._joints = JointReader(self._names)
        self.last_time: float | None = None  # [s] of the last joint_states used
        self._next_publish: float | None = None  # [s] joint_states time of the next odom

    def check(self, names: Sequence[str], positions: Sequence[float],
              velocities: Sequence[float]) -> None:
        """Raise ``ImpossibleReading`` for a swivel reading past its stop or too fast."""
        check_swivel_reading(self._names[0], names, positions, velocities,
                             self.car.max_swivel_angle)

    def update(self, t: float, names: Sequence[str], positions: Sequence[float],
               velocities: Sequence[float]) -> bool:
        """
        Integrate the state of time ``t`` [s]; return whether an odometry message is due now.

        Positions [rad] and velocities [rad/s] are in the order of ``names``. Time going back
        (a sim reset) restarts the integration, the pose kept.

        Raises
        ------
        swivel_car_control.joints.MissingJointError
            A joint is missing, or an ``ImpossibleReading``; the odometry is not updated.
        ValueError
            The model refuses the values; the odometry is not updated.

        """
        self.check(names, positions, velocities)
        if self.last_time is not None and t < self.last_time:
            self._joints.reset()
            self.last_time = None
            self._next_publish = None
        joints = self._joints.read(t, names, positions, velocities)
        swivel_name, left_name, right_name = self._names
        swivel = joints[swivel_name]
        limit = self.car.max_swivel_angle
        theta2 = swivel.position
        if abs(theta2) <= limit + LIMIT_SLACK:
            theta2 = max(-limit, min(limit, theta2))
        left, right = joints[left_name].rate, joints[right_name].rate
        difference = right - left if self._rear_wheels_yaw else None
        dt = 0.0 if self.last_time is None else t - self.last_time
        self.odometry.update(theta2, swivel.rate, 0.5 * (left + right), dt, difference)
        self.last_time = t
        period = self._period
        if self._next_publish is None or t >= self._next_publish - 1e-9:
            due = (t if self._next_publish is None else self._next_publish) + period
            self._next_publish = due if due > t else t + period
            return True
        return False
