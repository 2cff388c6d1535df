"""Message <-> plain value conversions shared by the nodes."""

from __future__ import annotations

from geometry_msgs.msg import Quaternion

from swivel_car_control.core.joint_states import yaw_quaternion


def yaw_to_quaternion(yaw: float) -> Quaternion:
    """Rotation about z by ``yaw`` [rad]."""
    x, y, z, w = yaw_quaternion(yaw)
    return Quaternion(x=x, y=y, z=z, w=w)
