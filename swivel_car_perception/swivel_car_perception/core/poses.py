"""A short history of odometry's planar poses, looked up at an image's stamp; ROS-free."""

from __future__ import annotations

from collections import deque
import math

from swivel_car_perception.core.fusion import Pose2D


class PoseHistory:
    """
    The last ``span`` [s] of planar poses (stamps in nanoseconds, increasing).

    ``at`` interpolates between the two poses around a stamp; None outside the history.
    A stamp older than the last one clears the history (odometry or the sim was reset).
    """

    def __init__(self, span: float = 2.0) -> None:
        self._span = round(span * 1e9)  # [ns]
        self._poses: deque[tuple[int, Pose2D]] = deque()

    def add(self, stamp: int, pose: Pose2D) -> None:
        """Remember ``pose`` at ``stamp`` [ns]."""
        if self._poses and stamp < self._poses[-1][0]:
            self._poses.clear()
        self._poses.append((stamp, pose))
        while self._poses[0][0] < stamp - self._span:
            self._poses.popleft()

    def clear(self) -> None:
        """Forget every pose."""
        self._poses.clear()

    @property
    def latest(self) -> tuple[int, Pose2D] | None:
        """Return the newest (stamp [ns], pose), or None."""
        return self._poses[-1] if self._poses else None

    def at(self, stamp: int) -> Pose2D | None:
        """Return the pose at ``stamp`` [ns], interpolated, or None outside the history."""
        poses = self._poses
        if not poses or not poses[0][0] <= stamp <= poses[-1][0]:
            return None
        for (t0, p0), (t1, p1) in zip(poses, list(poses)[1:]):
            if t0 <= stamp <= t1:
                f = 0.0 if t1 == t0 else (stamp - t0) / (t1 - t0)
                turn = math.atan2(math.sin(p1.yaw - p0.yaw), math.cos(p1.yaw - p0.yaw))
                return Pose2D(p0.x + f * (p1.x - p0.x), p0.y + f * (p1.y - p0.y),
                              p0.yaw + f * turn)
        return poses[-1][1]
