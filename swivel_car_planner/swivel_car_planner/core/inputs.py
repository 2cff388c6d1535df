"""
The planner's inputs as plain values, ROS-free.

What the node takes from each message, and the ``Observation`` one synchronised moment
(``core.sync.Tick``) makes.

The planner node calls these on its messages' fields and the in-process stack
(``swivel_car_studies.inprocess``) on the cores' outputs, so both hand the state machine the
same floats. A non-finite field is refused here, where it enters (a ValueError naming the
message's field): one NaN in an observation would reach a command.
"""

from __future__ import annotations

import math
from typing import Sequence

from swivel_car_model.checks import check_finite_number

from swivel_car_planner.core.state_machine import Command, Observation, Outcome
from swivel_car_planner.core.sync import Tick

IMU = 'imu'
ODOM = 'odom'
# The swivel comes in it too: the controller measured it from the joint_states it answers,
# with the same stamp, so the planner need not take every joint_states as well (one message
# fewer per control period through the chain's busiest publisher).
CONTROLLER_STATE = 'controller/controller_state'
# Every input topic; a tick comes with each controller state.
INPUTS = (IMU, ODOM, CONTROLLER_STATE)

# After a failed climb the planner releases the swivel to the controller's hold.
RELEASE = Command(0.0, 0.0, 0.0, False)


def roll_pitch(x: float, y: float, z: float, w: float) -> tuple[float, float]:
    """Return roll and pitch of a quaternion (REP-103 fixed-axis roll, pitch, yaw) [rad]."""
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    return roll, pitch


def yaw_of(x: float, y: float, z: float, w: float) -> float:
    """Return the yaw of a quaternion [rad]."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _check_finite(*fields: tuple[str, float]) -> None:
    """Refuse a non-finite field: ValueError names it as the message does."""
    for name, value in fields:
        check_finite_number(name, value)


def _quaternion(name: str, value: Sequence[float]) -> list[tuple[str, float]]:
    return [(f'{name}.{axis}', number) for axis, number in zip('xyzw', value)]


def odom_values(x: float, y: float, orientation: Sequence[float],
                speed: float) -> tuple[float, float, float, float]:
    """
    Return the planner's values of ``odom``; ValueError names a non-finite field.

    Position x, y [m], orientation quaternion (x, y, z, w), forward speed [m/s] -> (x [m],
    y [m], yaw [rad], speed [m/s]).
    """
    _check_finite(('pose.pose.position.x', x), ('pose.pose.position.y', y),
                  *_quaternion('pose.pose.orientation', orientation),
                  ('twist.twist.linear.x', speed))
    return x, y, yaw_of(*orientation), speed


def imu_values(orientation: Sequence[float]) -> tuple[float, float, float]:
    """``imu`` orientation quaternion (x, y, z, w) -> (roll, pitch, yaw) [rad]; see odom."""
    _check_finite(*_quaternion('orientation', orientation))
    return (*roll_pitch(*orientation), yaw_of(*orientation))


def controller_state_values(set_point: float, torque: float, command_stamp: float,
                            swivel: float, swivel_rate: float
                            ) -> tuple[float, float, float, float, float]:
    """
    Return the planner's values of ``controller/controller_state``.

    (set point [rad], torque [N m], stamp of the last swivel_command the controller heard
    [s], -inf for none, measured swivel angle [rad] and rate [rad/s]). ValueError names a
    non-finite field.
    """
    _check_finite(('set_point', set_point), ('measured', swivel),
                  ('measured_rate', swivel_rate), ('torque', torque))
    return set_point, torque, command_stamp, swivel, swivel_rate


def command_heard(tick: Tick) -> float:
    """Return the stamp [s] of the last swivel_command the controller had heard at ``tick``."""
    return tick.values[CONTROLLER_STATE][2]


def observation(tick: Tick) -> Observation:
    """Make the state machine's view of one synchronised moment of all ``INPUTS``."""
    x, y, yaw, speed = tick.values[ODOM]
    roll, pitch, imu_yaw = tick.values[IMU]
    set_point, torque, _, swivel, swivel_rate = tick.values[CONTROLLER_STATE]
    return Observation(
        time=tick.time, x=x, y=y, yaw=yaw, swivel=swivel, swivel_rate=swivel_rate,
        set_point=set_point, torque=torque, roll=roll, pitch=pitch, imu_yaw=imu_yaw,
        speed=speed)


def end_commands(outcome: Outcome) -> list[Command]:
    """
    Return what the planner sends when a climb has ended, after the state machine's last command.

    After a failure the swivel holds where it is (that last command) and is released, so the
    controller keeps holding it and cmd_vel steers again.
    """
    return [] if outcome.success else [RELEASE]


class RefusalLog:
    """
    Says at most once per ``interval`` per topic why its inputs are refused.

    Parameters
    ----------
    interval : float
        Between two lines about one topic. # [s]

    """

    def __init__(self, interval: float) -> None:
        self._interval = interval
        self._next: dict[str, float] = {}  # topic -> time [s] its next line is due
        self._held: dict[str, int] = {}  # topic -> refusals since its last line

    def line(self, topic: str, reason: str, now: float) -> str | None:
        """Return the line to log about refusing ``topic`` at ``now`` [s], None if not due."""
        held = self._held.get(topic, 0)
        if now < self._next.get(topic, -math.inf):
            self._held[topic] = held + 1
            return None
        self._next[topic], self._held[topic] = now + self._interval, 0
        more = f' ({held} more refused since the last line)' if held else ''
        return f'{topic} refused: {reason}: not acted on{more}'
