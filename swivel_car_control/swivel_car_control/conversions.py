"""Message <-> plain value conversions shared by the nodes."""

from __future__ import annotations

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Quaternion

from swivel_car_control.core.joint_states import yaw_quaternion


def is_zero_stamp(stamp: Time) -> bool:
    return stamp.sec == 0 and stamp.nanosec == 0


def yaw_to_quaternion(yaw: float) -> Quaternion:
    """Rotation about z by ``yaw`` [rad]."""
    x, y, z, w = yaw_quaternion(yaw)
    return Quaternion(x=x, y=y, z=z, w=w)
