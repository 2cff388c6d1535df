"""
Judging a climb by the sim's ground truth, ROS-free.

Shared by the system tests (from ``ground_truth/odom``) and the in-process stack
(``swivel_car_studies.inprocess``, from the sim core's state).
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Sequence

from swivel_car_planner.core.inputs import roll_pitch, yaw_of


@dataclass(frozen=True)
class GroundTruth:
    """base_link in the world frame (the sim's ground truth)."""

    x: float  # [m]
    y: float  # [m]
    z: float  # [m]
    roll: float  # [rad]
    pitch: float  # [rad] REP-103: positive nose down
    yaw: float  # [rad]
    speed: float  # [m/s] |linear velocity|

    @classmethod
    def from_pose(cls, position: Sequence[float], orientation: Sequence[float],
                  velocity: Sequence[float]) -> GroundTruth:
        """
        Make the ground truth from base_link's position, orientation and linear velocity.

        Position [m], orientation quaternion (x, y, z, w), linear velocity [m/s] (any frame:
        only its norm is kept).
        """
        roll, pitch = roll_pitch(*orientation)
        vx, vy, vz = velocity
        return cls(float(position[0]), float(position[1]), float(position[2]), roll, pitch,
                   yaw_of(*orientation), math.sqrt(vx ** 2 + vy ** 2 + vz ** 2))

    @classmethod
    def from_msg(cls, msg) -> GroundTruth:
        """From a nav_msgs/Odometry (``ground_truth/odom``)."""
        p, q, v = msg.pose.pose.position, msg.pose.pose.orientation, msg.twist.twist.linear
        return cls.from_pose((p.x, p.y, p.z), (q.x, q.y, q.z, q.w), (v.x, v.y, v.z))

    def four_wheels_on_top(self, height: float, wheel_radius: float,
                           tolerance: float = 0.01) -> bool:
        """
        Tell whether the rear axle (base_link) is at step height and the car level.

        With the rear wheels up, the front ones, a wheelbase ahead, are too. height,
        wheel_radius, tolerance [m]
        """
        return (abs(self.z - (height + wheel_radius)) < tolerance
                and abs(self.pitch) < 0.05 and abs(self.roll) < 0.05)

    def front_on_top(self, height: float, wheel_radius: float, wheelbase: float,
                     tolerance: float = 0.015) -> bool:
        """
        Tell whether the front axle (``wheelbase`` ahead of base_link) is at step height.

        height, wheel_radius, wheelbase, tolerance [m]
        """
        front = self.z - wheelbase * math.sin(self.pitch)
        return front > height + wheel_radius - tolerance
