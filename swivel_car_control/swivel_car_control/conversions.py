"""Message <-> plain value conversions shared by the nodes."""

from __future__ import annotations

from geometry_msgs.msg import Quaternion

from swivel_car_control.core.joint_states import yaw_quaternion


def set_yaw(quaternion: Quaternion, yaw: float) -> None:
    """Set ``quaternion`` to the rotation about z by ``yaw`` [rad]."""
    quaternion.x, quaternion.y, quaternion.z, quaternion.w = yaw_quaternion(yaw)
