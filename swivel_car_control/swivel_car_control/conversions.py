"""Message <-> plain value conversions shared by the nodes."""

from __future__ import annotations

import math

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Quaternion


def stamp_to_seconds(stamp: Time) -> float:
    """builtin_interfaces/Time to seconds. # [s]"""
    return stamp.sec + stamp.nanosec * 1e-9


def is_zero_stamp(stamp: Time) -> bool:
    return stamp.sec == 0 and stamp.nanosec == 0


def yaw_to_quaternion(yaw: float) -> Quaternion:
    """Rotation about z by ``yaw`` [rad]."""
    return Quaternion(x=0.0, y=0.0, z=math.sin(0.5 * yaw), w=math.cos(0.5 * yaw))
