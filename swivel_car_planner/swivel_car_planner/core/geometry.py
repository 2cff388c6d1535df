"""
Planar geometry of the step edge relative to the car (ground projection, REP-103).

The step edge is a straight line on the ground. ``StepEdge`` holds it in the odometry frame,
fixed when the climb starts, and measures signed distances of points to it: negative before
the edge, positive over the step.
"""

from __future__ import annotations

from dataclasses import dataclass
import math


def wrap_angle(angle: float) -> float:
    """Return ``angle`` wrapped to [-pi, pi) [rad]."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@dataclass(frozen=True)
class Pose2D:
    x: float  # [m]
    y: float  # [m]
    yaw: float  # [rad]

    def transform(self, bx: float, by: float) -> tuple[float, float]:
        """Return a point given in this pose's frame in the parent frame [m]."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return self.x + c * bx - s * by, self.y + s * bx + c * by


@dataclass(frozen=True)
class StepEdge:
    """
    The step's near edge: a point on it and the unit normal pointing onto the step.

    Parameters
    ----------
    px, py : a point of the edge. # [m]
    normal_yaw : direction of the normal into the step. # [rad]

    """

    px: float  # [m]
    py: float  # [m]
    normal_yaw: float  # [rad]

    @classmethod
    def from_request(cls, pose: Pose2D, front_axle_x: float, step_distance: float,
                     step_yaw: float) -> StepEdge:
        """
        Make the edge a request names, relative to the car at ``pose``.

        ``step_distance`` runs along base_link x from the front axle's ground contact
        (``front_axle_x`` ahead of base_link); the edge lies at ``step_yaw`` to base_link's
        y axis, so its normal points at ``step_yaw`` from base_link's x axis.
        """
        px, py = pose.transform(front_axle_x + step_distance, 0.0)
        return cls(px, py, wrap_angle(pose.yaw + step_yaw))

    def signed_distance(self, x: float, y: float) -> float:
        """Return how far the point (x, y) lies past the edge along its normal [m]."""
        return ((x - self.px) * math.cos(self.normal_yaw)
                + (y - self.py) * math.sin(self.normal_yaw))

    def along(self, x: float, y: float) -> float:
        """
        Return where the point (x, y) lies along the edge from the edge's point [m].

        Leftwards (the normal turned +90 deg) is positive.
        """
        return (-(x - self.px) * math.sin(self.normal_yaw)
                + (y - self.py) * math.cos(self.normal_yaw))

    def relative_heading(self, yaw: float) -> float:
        """Return the car's heading relative to the normal, positive = turned left [rad]."""
        return wrap_angle(yaw - self.normal_yaw)
