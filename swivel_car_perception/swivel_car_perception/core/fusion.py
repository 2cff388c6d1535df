"""
Fusing a step's detections over frames as the car moves, with odometry; ROS-free.

Each detection is relative to base_link at its image's stamp. With the odometry's planar pose
at that stamp it becomes a line in ``odom`` (the edge's normal angle and its distance from
odom's origin), a height, and the two ends' positions along the line. Those are averaged over
the frames, each weighted by its inverse variance; the car's motion adds a little variance
to the estimate (odometry drifts by about ``drift`` of the path), so the estimate follows a
slowly drifting odometry. A detection that disagrees with the estimate by more than
``gate`` sigmas starts a new one (another step, or the first estimate was wrong); after
``max_misses`` frames without a detection the estimate is dropped.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from swivel_car_perception.core.detector import Detection

GATE_FLOOR = (0.03, 0.05, 0.015)  # [m], [rad], [m] distance, yaw, height always accepted


@dataclass(frozen=True)
class Pose2D:
    """A planar pose in odom: x [m], y [m], yaw [rad]."""

    x: float
    y: float
    yaw: float


@dataclass
class _Track:
    """The fused step in odom."""

    angle: float  # [rad] the edge's normal, in odom
    rho: float  # [m] the edge line: normal . p = rho
    height: float  # [m]
    rho_var: float  # [m^2]
    angle_var: float  # [rad^2]
    height_var: float  # [m^2]
    left: float  # [m] ends along the edge (leftwards from the normal's foot)
    right: float  # [m]
    left_seen: bool
    right_seen: bool
    width_var: float  # [m^2]
    depth_seen: float  # [m]
    pose: Pose2D  # where the car was at the last update
    frames: int = 1
    misses: int = 0


class StepTracker:
    """
    The fused estimate of the nearest step.

    Parameters
    ----------
    front_axle : float
        The front axle's ground contact along base_link x. # [m]
    drift : float
        Odometry's drift per metre driven (1 sigma). # [1]
    gate : float
        Sigmas beyond which a detection starts a new estimate. # [1]
    max_misses : int
        Frames without a detection before the estimate is dropped. # [1]

    """

    def __init__(self, front_axle: float, drift: float = 0.02, gate: float = 5.0,
                 max_misses: int = 3) -> None:
        self.front_axle = front_axle
        self.drift = drift
        self.gate = gate
        self.max_misses = max_misses
        self._track: _Track | None = None

    @property
    def frames(self) -> int:
        """Return how many detections the present estimate fuses (0: none)."""
        return self._track.frames if self._track else 0

    def reset(self) -> None:
        """Forget the estimate (odometry was reset)."""
        self._track = None

    def update(self, detection: Detection, pose: Pose2D) -> Detection:
        """
        Fuse ``detection`` (relative to base_link at ``pose``) and return the estimate.

        The estimate is relative to base_link at ``pose``; not found when this frame found
        nothing (the reason is the frame's).
        """
        track = self._track
        if not detection.found:
            if track is not None:
                track.misses += 1
                if track.misses > self.max_misses:
                    self._track = None
            return detection
        new = self._from_detection(detection, pose)
        if track is None or not self._agrees(track, new, pose):
            self._track = new
        else:
            self._fuse(track, new, pose)
        return self.estimate(pose, detection)

    def estimate(self, pose: Pose2D, detection: Detection) -> Detection:
        """Return the fused step relative to base_link at ``pose`` (tilt from ``detection``)."""
        t = self._track
        yaw = _wrap(t.angle - pose.yaw)
        # Where base_link's x axis meets the edge: p = pose + s (cos, sin), n . p = rho.
        cos_yaw = math.cos(yaw)
        crossing = (t.rho - pose.x * math.cos(t.angle) - pose.y * math.sin(t.angle)) / cos_yaw
        # Ends along the edge, leftwards from the normal's foot, minus the crossing's.
        foot_to_crossing = _along(t.angle, pose.x + crossing * math.cos(pose.yaw),
                                  pose.y + crossing * math.sin(pose.yaw))
        left, right = t.left - foot_to_crossing, t.right - foot_to_crossing
        distance_std = math.sqrt(t.rho_var) / abs(cos_yaw)
        return Detection(
            True, '', t.height, crossing - self.front_axle, yaw, left - right,
            (left + right) / 2.0, t.depth_seen, math.sqrt(t.height_var), distance_std,
            math.sqrt(t.angle_var), math.sqrt(t.width_var), t.left_seen, t.right_seen,
            detection.ground_pitch, detection.ground_roll)

    def _from_detection(self, d: Detection, pose: Pose2D) -> _Track:
        angle = _wrap(pose.yaw + d.yaw)
        crossing = self.front_axle + d.distance  # [m] along base_link x
        px = pose.x + crossing * math.cos(pose.yaw)
        py = pose.y + crossing * math.sin(pose.yaw)
        rho = px * math.cos(angle) + py * math.sin(angle)
        base = _along(angle, px, py)
        rho_var = (d.distance_std * math.cos(d.yaw)) ** 2
        return _Track(angle, rho, d.height, rho_var, d.yaw_std ** 2, d.height_std ** 2,
                      base + d.offset + d.width / 2.0, base + d.offset - d.width / 2.0,
                      d.left_end_seen, d.right_end_seen, d.width_std ** 2, d.depth_seen, pose)

    def _agrees(self, track: _Track, new: _Track, pose: Pose2D) -> bool:
        self._grow(track, pose)
        limits = [max(self.gate * math.sqrt(a + b), floor) for a, b, floor in (
            (track.rho_var, new.rho_var, GATE_FLOOR[0]),
            (track.angle_var, new.angle_var, GATE_FLOOR[1]),
            (track.height_var, new.height_var, GATE_FLOOR[2]))]
        return (abs(track.rho - new.rho) < limits[0]
                and abs(_wrap(track.angle - new.angle)) < limits[1]
                and abs(track.height - new.height) < limits[2])

    def _grow(self, track: _Track, pose: Pose2D) -> None:
        """Add the odometry drift of the path since the last update to the estimate."""
        path = math.hypot(pose.x - track.pose.x, pose.y - track.pose.y)
        track.rho_var += (self.drift * path) ** 2
        track.angle_var += (self.drift * path) ** 2  # [rad] heading drift per metre, alike
        track.pose = pose

    def _fuse(self, t: _Track, n: _Track, pose: Pose2D) -> None:
        def mean(a: float, va: float, b: float, vb: float) -> tuple[float, float]:
            return (a * vb + b * va) / (va + vb), va * vb / (va + vb)

        t.rho, t.rho_var = mean(t.rho, t.rho_var, n.rho, n.rho_var)
        t.angle = _wrap(t.angle + mean(0.0, t.angle_var, _wrap(n.angle - t.angle),
                                       n.angle_var)[0])
        t.angle_var = t.angle_var * n.angle_var / (t.angle_var + n.angle_var)
        t.height, t.height_var = mean(t.height, t.height_var, n.height, n.height_var)
        for end, outward in (('left', max), ('right', min)):
            seen_before, seen_now = getattr(t, f'{end}_seen'), getattr(n, f'{end}_seen')
            old, new = getattr(t, end), getattr(n, end)
            if seen_before and seen_now:
                value = (old + new) / 2.0
            elif seen_now:
                value = new
            elif seen_before:
                value = old
            else:  # neither frame saw past it: the face reaches at least this far
                value = outward(old, new)
            setattr(t, end, value)
            setattr(t, f'{end}_seen', seen_before or seen_now)
        t.width_var = min(t.width_var, n.width_var)
        t.depth_seen = max(t.depth_seen, n.depth_seen)
        t.frames += 1
        t.misses = 0


def _along(angle: float, x: float, y: float) -> float:
    """Position of (x, y) [m] along an edge of normal ``angle``, leftwards [m]."""
    return -x * math.sin(angle) + y * math.cos(angle)


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def moved(detection: Detection, then: Pose2D, now: Pose2D, front_axle: float) -> Detection:
    """
    Return ``detection``, seen from base_link at ``then``, relative to base_link at ``now``.

    Both poses are odometry's; the uncertainties are the detection's (no drift added).
    """
    tracker = StepTracker(front_axle, drift=0.0)
    tracker.update(detection, then)
    return tracker.estimate(now, detection)
