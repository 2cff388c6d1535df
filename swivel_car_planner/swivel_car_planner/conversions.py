"""Conversions between messages and the planner core's types."""

from __future__ import annotations

from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu
from swivel_car_msgs.msg import ClimbOutcome, ClimbPlan as ClimbPlanMsg, SwivelControllerState

from swivel_car_planner.core import ClimbPlan, ClimbRequest, Outcome
from swivel_car_ros.serialized import MessageReader


def request_from(message, with_time_allowance: bool) -> ClimbRequest:
    """Make a core request from a srv/ClimbStep request or an action/ClimbStep goal."""
    return ClimbRequest(
        step_height=float(message.step_height), step_distance=float(message.step_distance),
        step_yaw=float(message.step_yaw), plan_only=bool(message.plan_only),
        time_allowance=float(message.time_allowance) if with_time_allowance else 0.0,
        step_width=float(message.step_width), step_offset=float(message.step_offset))


def plan_to_msg(plan: ClimbPlan) -> ClimbPlanMsg:
    msg = ClimbPlanMsg()
    for name in ('swivel_angle', 'lift_angle', 'wheel_clearance', 'approach_distance',
                 'approach_heading', 'peak_torque', 'energy', 'max_scalable_step',
                 'tip_over_margin', 'interference_margin', 'duration', 'backup_distance'):
        setattr(msg, name, float(getattr(plan, name)))
    msg.procedure = int(plan.procedure)
    msg.reposition_swivel = [float(s.swivel) for s in plan.reposition]
    msg.reposition_length = [float(s.length) for s in plan.reposition]
    return msg


def outcome_to_msg(outcome: Outcome) -> ClimbOutcome:
    return ClimbOutcome(
        duration=float(outcome.duration), peak_torque=float(outcome.peak_torque),
        energy=float(outcome.energy), max_pitch=float(outcome.max_pitch),
        distance_travelled=float(outcome.distance_travelled))


# The planner reads its inputs serialized (swivel_car_ros.serialized): deserialising a whole
# nav_msgs/Odometry (two 6x6 covariances) took 134 us and an Imu 45 us of a 10 ms control
# period on this machine; the few fields it uses are read at their CDR offsets here.
_STAMP = ('header.stamp.sec', 'header.stamp.nanosec')
_ODOM = MessageReader(Odometry, _STAMP + tuple(f'pose.pose.position.{c}' for c in 'xy') + tuple(
    f'pose.pose.orientation.{c}' for c in 'xyzw') + ('twist.twist.linear.x',))
_CONTROLLER_STATE = MessageReader(SwivelControllerState, _STAMP + (
    'set_point', 'measured', 'measured_rate', 'torque', 'swivel_command_stamp.sec',
    'swivel_command_stamp.nanosec'))
_IMU = MessageReader(Imu, _STAMP + tuple(f'orientation.{c}' for c in 'xyzw')
                     + tuple(f'angular_velocity.{c}' for c in 'xyz'))


def odom_fields(data: bytes) -> tuple[Time, float, float, tuple[float, float, float, float],
                                      float]:
    """
    Read a serialized nav_msgs/Odometry.

    Returns stamp, position x, y [m], orientation quaternion (x, y, z, w) and forward speed
    (twist.linear.x) [m/s].
    """
    sec, nanosec, x, y, *orientation, speed = _ODOM(data)
    return Time(sec=sec, nanosec=nanosec), x, y, tuple(orientation), speed


def controller_state_fields(data: bytes) -> tuple[Time, float, float, float, float, Time]:
    """
    Read a serialized swivel_car_msgs/SwivelControllerState.

    Returns stamp, set point [rad], measured swivel angle [rad] and rate [rad/s], torque [N m]
    and the stamp of the last swivel_command the controller heard (zero: none).
    """
    sec, nanosec, set_point, measured, measured_rate, torque, heard_sec, heard_nanosec = (
        _CONTROLLER_STATE(data))
    return (Time(sec=sec, nanosec=nanosec), set_point, measured, measured_rate, torque,
            Time(sec=heard_sec, nanosec=heard_nanosec))


def imu_fields(data: bytes) -> tuple[Time, tuple[float, float, float, float],
                                     tuple[float, float, float]]:
    """
    Read a serialized sensor_msgs/Imu.

    Returns its stamp, orientation quaternion (x, y, z, w) and angular velocity [rad/s].
    """
    sec, nanosec, *values = _IMU(data)
    return Time(sec=sec, nanosec=nanosec), tuple(values[:4]), tuple(values[4:])
