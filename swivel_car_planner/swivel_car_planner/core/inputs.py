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

from swivel_car_planner.core.geometry import wrap_angle
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


class Attitude:
    """
    The roll and pitch the planner trusts: the gyro's integral, the fused angles as reference.

    A complementary filter. An IMU board's fused roll and pitch follow its accelerometer's
    gravity with the bandwidth of the board's own filter, so they take a jolt's acceleration
    (the riser's push on a wheel, a wheel landing, the car braking) for a tilt of about that
    acceleration over g: after a climb's jolts the sim's realistic board (a Mahony filter at
    1/s) is 0.03-0.05 rad off for a second or two, more than the 0.023 rad by which the planner
    tells a car on top of a 2 cm step from one with only its front up. The gyro feels no
    acceleration: its integral over seconds is off by its residual bias times that time (the
    realistic BMI088 calibrated at rest: 0.0002 rad/s, 0.002 rad in 10 s). So roll and pitch
    change with the gyro's rates, and are pulled towards the fused angles only at frequencies
    below 1 / (2 pi ``time_constant``), where the board's filter is right on average. Yaw is
    the fused yaw as it comes: nothing references it better (the planner weighs it against
    odometry's).

    Parameters
    ----------
    time_constant : float
        Of the pull towards the fused angles, > 0. # [s]

    Notes
    -----
    The gyro's body rates (p, q, r) turn into roll and pitch rates at the filter's own angles
    (roll' = p + tan(pitch) (q sin(roll) + r cos(roll)), pitch' = q cos(roll) - r sin(roll)),
    integrated by the trapezoid between two samples. The first sample, one after time went
    back (a sim reset) or after a gap longer than ``MAX_GAP`` (the rate between is unknown)
    starts the filter at the fused angles; a sample of a stamp already taken changes nothing.

    """

    MAX_GAP = 0.25  # [s] 25 samples of a 100 Hz IMU: beyond it the integral is a guess

    def __init__(self, time_constant: float) -> None:
        check_finite_number('time_constant', time_constant)
        if time_constant <= 0.0:
            raise ValueError(f'time_constant must be > 0, got {time_constant!r}')
        self.time_constant = time_constant  # [s]
        self._stamp = -math.inf  # [s]
        self._rate = (0.0, 0.0, 0.0)  # [rad/s] body rates of the last sample
        self._angles = (0.0, 0.0, 0.0)  # [rad] roll, pitch, yaw

    def update(self, stamp: float, orientation: Sequence[float],
               angular_velocity: Sequence[float]) -> tuple[float, float, float]:
        """
        Take one ``imu`` sample; return (roll, pitch, yaw) [rad] at ``stamp`` [s].

        ``orientation``: the fused quaternion (x, y, z, w); ``angular_velocity``: the gyro's
        body rates [rad/s]. ValueError names a non-finite field and changes nothing.
        """
        _check_finite(*_quaternion('orientation', orientation),
                      *[(f'angular_velocity.{axis}', value)
                        for axis, value in zip('xyz', angular_velocity)])
        fused_roll, fused_pitch = roll_pitch(*orientation)
        yaw = yaw_of(*orientation)
        dt = stamp - self._stamp  # [s]
        if dt == 0.0:
            return self._angles
        if not 0.0 < dt <= self.MAX_GAP:
            roll, pitch = fused_roll, fused_pitch
        else:
            roll, pitch, _ = self._angles
            p, q, r = (0.5 * (a + b) for a, b in zip(self._rate, angular_velocity))
            roll_rate = p + math.tan(pitch) * (q * math.sin(roll) + r * math.cos(roll))
            pitch_rate = q * math.cos(roll) - r * math.sin(roll)
            roll, pitch = roll + roll_rate * dt, pitch + pitch_rate * dt
            pull = 1.0 - math.exp(-dt / self.time_constant)  # [1]
            roll += pull * wrap_angle(fused_roll - roll)
            pitch += pull * (fused_pitch - pitch)
        self._stamp, self._rate = stamp, tuple(float(v) for v in angular_velocity)
        self._angles = (wrap_angle(roll), pitch, yaw)
        return self._angles


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
