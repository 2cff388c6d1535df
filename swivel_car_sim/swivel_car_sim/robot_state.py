"""What the simulated robot's sensors and the ground truth report at one instant; ROS-free."""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np


@dataclass(frozen=True)
class RobotState:
    """
    What the sensors and the ground truth report at one instant.

    Attributes
    ----------
    time : float  # [s] sim time
    joint_names : tuple of str  # steer joint, then the four wheel joints
    positions : numpy.ndarray  # [rad]
    velocities : numpy.ndarray  # [rad/s]
    efforts : numpy.ndarray  # [N m] torques applied during the last step
    position : numpy.ndarray  # [m] base_link origin in the world
    orientation : numpy.ndarray  # [1] base_link orientation, quaternion x, y, z, w
    linear_velocity : numpy.ndarray  # [m/s] base_link origin velocity, in base_link
    angular_velocity : numpy.ndarray  # [rad/s] in base_link
    linear_acceleration : numpy.ndarray  # [m/s^2] specific force (IMU), in base_link

    """

    time: float
    joint_names: tuple[str, ...]
    positions: np.ndarray
    velocities: np.ndarray
    efforts: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    linear_velocity: np.ndarray
    angular_velocity: np.ndarray
    linear_acceleration: np.ndarray

    @property
    def yaw(self) -> float:
        """Heading of base_link about the world z axis [rad]."""
        x, y, z, w = self.orientation
        return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))

    @property
    def pitch(self) -> float:
        """Pitch of base_link, positive nose down (REP-103 rotation about y) [rad]."""
        x, y, z, w = self.orientation
        return math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
