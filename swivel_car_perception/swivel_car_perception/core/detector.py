"""
The step detector on one depth image: ground plane, then the nearest step edge ahead; ROS-free.

From the depth image, its intrinsics and the camera's mounting on base_link (the robot
description's ``camera_mount``), every valid pixel becomes a point in base_link. The ground is
the plane fitted to the points near where the ground should be (the mounting says where),
refitted on its own inliers, so a car pitched by a degree or two still finds it. Points
higher than ``min_height`` above that plane are the step's. A step's riser faces the camera:
its points lie on one vertical plane, seen nearly face-on, so each locates the edge to about
the depth noise. The edge is the line fitted (weighted by each point's depth variance) to the
nearest raised points across the view; the height is the mean height of the top face's
points past the edge, seen at a grazing angle, where the depth error hardly moves a point up
or down. Each end of the edge counts as seen when the camera looks past it at ground farther
away; the width is the visible extent, grown by half a pixel's footprint at each seen end.

Frames: base_link at rest (x forward, y left, z up, the rear axle's middle at wheel-centre
height). The step's geometry is what ``spawn_obstacle`` and ``climb_step`` take: distance from
the front axle's ground contact to where base_link's x axis meets the edge, yaw of the edge's
normal from base_link's x axis (the edge's angle from base_link's y axis), width along the
edge and the face's centre along the edge (offset, leftwards).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from swivel_car_model.description import CarDescription

# A riser is a band of raised points this deep in front of the farthest riser point: the
# edge's pixel footprint at 2 m (18 mm) plus three depth sigmas there (45 mm).
RISER_BAND = 0.06  # [m]
ENDS_PROBE = 0.04  # [m] how far past an end of the edge the camera must see ground
RISER_SLACK = 0.005  # [m] a riser point past the edge line beyond its depth error
# The front wheels reach this far ahead of the front axle's ground contact when the swivel
# turns them (a wheel of radius r, swung forward by up to about 0.1 m): the camera sees
# them, and nothing nearer counts as a step.
SELF_REACH_MARGIN = 0.1  # [m]
GROUND_HYPOTHESES = 80  # planes tried for the ground (through its point below the car)
NEAREST_SHARE = 4  # half the planes through two of the nearest quarter of the points
# A point this far under a plane, and three of its depth errors, is below it: the ground has
# none below it; a plane sloping from it onto a step's top face has the ground in front.
BELOW_MARGIN = 0.003  # [m]
MAX_TILT = 0.2  # [rad] steepest ground plane: the car pitched or rolled on flat ground


@dataclass(frozen=True)
class Intrinsics:
    """A pinhole camera without distortion (CameraInfo's K); 0-based pixels."""

    width: int  # [px]
    height: int  # [px]
    fx: float  # [px]
    fy: float  # [px]
    cx: float  # [px]
    cy: float  # [px]


@dataclass(frozen=True)
class Mount:
    """
    Where the optical frame sits in base_link at rest, and the car's geometry.

    Attributes
    ----------
    rotation : numpy.ndarray
        Optical axes (x right, y down, z forward) as columns, in base_link. # [1]
    position : numpy.ndarray
        The optical centre in base_link. # [m]
    ground_height : float
        The ground below base_link at rest (the wheel radius). # [m]
    front_axle : float
        The front axle's ground contact along base_link x (the wheelbase). # [m]
    self_reach : float
        Points nearer than this along base_link x are the car's own front (front axle, wheels
        turned by the swivel). # [m]

    """

    rotation: np.ndarray
    position: np.ndarray
    ground_height: float
    front_axle: float
    self_reach: float

    @classmethod
    def of(cls, description: CarDescription) -> 'Mount':
        """Return the mounting the robot description states."""
        position, rotation = description.camera_optical_pose()
        return cls(rotation, position, description.r, description.wheelbase,
                   description.wheelbase + description.r + SELF_REACH_MARGIN)


@dataclass(frozen=True)
class DetectorConfig:
    """
    The detector's settings.

    Attributes
    ----------
    min_height : float
        Lowest step reported; raised points are those this much above the ground. # [m]
    max_distance : float
        Farthest edge reported, from the front axle's ground contact. # [m]
    max_lateral : float
        Points farther aside than this from base_link's x axis are left out. # [m]
    min_riser_points : int
        Fewest riser points for an edge. # [1]
    min_ground_points : int
        Fewest ground points for a ground plane. # [1]
    ground_band : float
        How far from the expected ground a first ground point may be. # [m]
    sigma_per_metre_squared : float
        The camera's depth RMS error over depth squared (D435: 0.08 px / (424 px * 0.05 m)). #
        [1/m]

    """

    min_height: float = 0.012  # [m]
    max_distance: float = 2.2  # [m]
    max_lateral: float = 2.0  # [m]
    min_riser_points: int = 30
    min_ground_points: int = 300
    ground_band: float = 0.08  # [m]
    sigma_per_metre_squared: float = 0.08 / (424.0 * 0.05)  # [1/m]


@dataclass(frozen=True)
class Detection:
    """
    What one image (or the fusion of several) says about the nearest step ahead.

    Attributes
    ----------
    found : bool
    reason : str
        Why nothing was found ('' when found).
    height, distance, yaw, width, offset : float
        As StepObstacle and ClimbStep take them. # [m], [m], [rad], [m], [m]
    depth_seen : float
        How far past the edge the top face was seen. # [m]
    height_std, distance_std, yaw_std, width_std : float
        One-sigma uncertainties. # [m], [m], [rad], [m]
    left_end_seen, right_end_seen : bool
        Whether each end of the edge was in view (+y is left).
    ground_pitch, ground_roll : float
        The ground plane's tilt in base_link: base_link's own pitch and roll on flat ground.
        # [rad]

    """

    found: bool
    reason: str = ''
    height: float = 0.0
    distance: float = 0.0
    yaw: float = 0.0
    width: float = 0.0
    offset: float = 0.0
    depth_seen: float = 0.0
    height_std: float = 0.0
    distance_std: float = 0.0
    yaw_std: float = 0.0
    width_std: float = 0.0
    left_end_seen: bool = False
    right_end_seen: bool = False
    ground_pitch: float = 0.0
    ground_roll: float = 0.0


def nothing(reason: str) -> Detection:
    """Return 'no step', with the reason."""
    return Detection(False, reason)


class StepDetector:
    """
    Find the nearest step edge ahead in depth images of one camera.

    Parameters
    ----------
    intrinsics : Intrinsics
    mount : Mount
    config : DetectorConfig

    """

    def __init__(self, intrinsics: Intrinsics, mount: Mount,
                 config: DetectorConfig = DetectorConfig()) -> None:
        self.intrinsics = intrinsics
        self.mount = mount
        self.config = config
        k = intrinsics
        v, u = np.mgrid[0:k.height, 0:k.width]
        # Each pixel's ray in base_link, scaled to unit depth along the optical axis.
        rays = np.stack([(u - k.cx) / k.fx, (v - k.cy) / k.fy, np.ones(u.shape)], axis=-1)
        self._rays = rays.reshape(-1, 3) @ mount.rotation.T

    def detect(self, depth: np.ndarray) -> Detection:
        """
        Detect the nearest step ahead in ``depth`` [m] (height x width, NaN: no return).

        Raises
        ------
        ValueError
            ``depth`` is not of the intrinsics' size.

        """
        k, cfg, mount = self.intrinsics, self.config, self.mount
        if depth.shape != (k.height, k.width):
            raise ValueError(f'depth image is {depth.shape[1]}x{depth.shape[0]}, the camera '
                             f'is {k.width}x{k.height}')
        z = np.asarray(depth, dtype=np.float64).reshape(-1)
        valid = np.isfinite(z) & (z > 0.0)
        if not valid.any():
            return nothing('no depth in the image (no return anywhere)')
        index = np.flatnonzero(valid)
        z = z[index]
        points = mount.position + self._rays[index] * z[:, None]  # [m] base_link
        ahead = ((points[:, 0] > mount.self_reach)
                 & (points[:, 0] < mount.front_axle + cfg.max_distance + 1.0)
                 & (np.abs(points[:, 1]) < cfg.max_lateral))
        points, z, index = points[ahead], z[ahead], index[ahead]
        plane = self._ground(points, z)
        if plane is None:
            return nothing('no ground in view (the camera sees too little of the ground '
                           'ahead: the sky, a wall, or the car tilted)')
        normal, offset, plane_std = plane
        heights = points @ normal + offset  # [m] above the ground
        # The ground frame: base_link's origin and x axis dropped onto the plane.
        x_axis = np.array([1.0, 0.0, 0.0]) - normal * normal[0]
        x_axis /= np.linalg.norm(x_axis)
        y_axis = np.cross(normal, x_axis)
        origin = -normal * offset  # base_link's origin's foot on the ground
        flat = np.stack([(points - origin) @ x_axis, (points - origin) @ y_axis], axis=1)
        sigma = cfg.sigma_per_metre_squared * z * z  # [m] each point's depth error
        raised = heights > cfg.min_height
        if raised.sum() < cfg.min_riser_points:
            return self._finish(nothing('flat ground: nothing raised ahead'), normal)
        edge = self._edge(flat[raised], sigma[raised])
        if edge is None:
            return self._finish(nothing('no straight edge among the raised points'), normal)
        x0, slope, cov, riser = edge
        yaw = -math.atan(slope)
        distance = x0 - mount.front_axle
        if not 0.0 <= distance <= cfg.max_distance:
            return self._finish(nothing(f'the nearest edge is {distance:.2f} m from the front '
                                        f'axle, outside 0-{cfg.max_distance} m'), normal)
        normal_2d = np.array([math.cos(yaw), math.sin(yaw)])
        along_2d = np.array([-math.sin(yaw), math.cos(yaw)])
        past = (flat - [x0, 0.0]) @ normal_2d  # [m] beyond the edge line
        along = (flat - [x0, 0.0]) @ along_2d  # [m] leftwards from the x axis' crossing
        riser_along = along[raised][riser]
        low, high = float(riser_along.min()), float(riser_along.max())
        # Past the riser by more than three of its points' depth errors (which lie along
        # nearly horizontal rays): the top face's points, not the riser's.
        top = raised & (past > 0.01 + 3.0 * sigma) & (along > low) & (along < high)
        if top.sum() < 5:
            return self._finish(nothing('the top face is not in view'), normal)
        height, height_std = _robust_mean(heights[top], sigma[top])
        if height < cfg.min_height:
            return self._finish(nothing('the raised points are lower than min_height'), normal)
        # The line's own standard errors, with a floor for what a fit on a pixel grid leaves:
        # the riser's footprint (a pixel) shifts the fitted line by up to a few millimetres.
        distance_std = math.hypot(math.sqrt(cov[0, 0]), plane_std, 0.002)
        yaw_std = math.hypot(math.sqrt(cov[1, 1]) / (1.0 + slope * slope), 0.003)
        height_std = math.hypot(height_std, plane_std, 0.001)
        ends = []
        for end, sign in ((high, 1.0), (low, -1.0)):
            seen = self._end_seen(x0, yaw, end + sign * ENDS_PROBE, height, origin, normal,
                                  x_axis, y_axis, depth)
            footprint = float(np.median(z[raised][riser])) / k.fx  # [m] one pixel at the edge
            ends.append((end + sign * footprint / 2.0 if seen else end, seen))
        (left, left_seen), (right, right_seen) = ends
        width_std = math.hypot(float(np.median(z[raised][riser])) / k.fx / 2.0, 0.005)
        found = Detection(
            True, '', height, distance, yaw, left - right, (left + right) / 2.0,
            float(np.percentile(past[top], 95)), height_std, distance_std, yaw_std, width_std,
            left_seen, right_seen)
        return self._finish(found, normal)

    @staticmethod
    def _finish(detection: Detection, normal: np.ndarray) -> Detection:
        """Add the ground's tilt to ``detection``."""
        pitch = math.atan2(normal[0], normal[2])  # [rad] REP-103: nose down positive
        roll = math.atan2(-normal[1], normal[2])
        return Detection(**{**detection.__dict__, 'ground_pitch': pitch, 'ground_roll': roll})

    def _ground(self, points: np.ndarray, z: np.ndarray):
        """
        Fit the ground plane: (upward unit normal, offset so that n.p + d = height, std).

        The car stands on the ground: its rear wheels touch it, so the ground passes
        ``ground_height`` below base_link's origin however the swivel pitches or rolls the
        car. Planes through that point and two points near where the ground should be
        (within ``ground_band`` of it), half of them two of the nearest points in view (the
        ground in front of a near step, which its top face can outnumber several times),
        none steeper than ``MAX_TILT``; of those supported by at least ``min_ground_points``
        points, those with the fewest points clearly below them (the ground has none; a
        step's top face, or a plane sloping from the ground onto it, has the ground in front
        of the step below it), of those the best supported. Then least squares on every
        point near that plane, weighted by the depth variance, refitted on its inliers.
        """
        cfg, mount = self.config, self.mount
        near = np.abs(points[:, 2] + mount.ground_height) < cfg.ground_band
        if near.sum() < cfg.min_ground_points:
            return None
        candidates = points[near]
        foot = np.array([0.0, 0.0, -mount.ground_height])  # [m] base_link's origin's foot
        nearest = np.argsort(candidates[:, 0], kind='stable')[
            :max(2, len(candidates) // NEAREST_SHARE)]
        rng = np.random.default_rng(0)  # the same hypotheses for the same image
        pairs = rng.integers(0, len(candidates), (GROUND_HYPOTHESES, 2))
        pairs[:GROUND_HYPOTHESES // 2] = nearest[
            rng.integers(0, len(nearest), (GROUND_HYPOTHESES // 2, 2))]
        normals = np.cross(candidates[pairs[:, 0]] - foot, candidates[pairs[:, 1]] - foot)
        length = np.linalg.norm(normals, axis=1)
        usable = length > 1e-9
        normals = normals[usable] / length[usable, None] * np.sign(normals[usable, 2:3])
        offsets = -normals @ foot
        upright = normals[:, 2] > math.cos(MAX_TILT)
        normals, offsets = normals[upright], offsets[upright]
        if len(normals) == 0:
            return None
        residual = candidates @ normals.T + offsets  # [m] each point (row) above each plane
        support = (np.abs(residual) < 0.01).sum(axis=0)
        sigma = cfg.sigma_per_metre_squared * z[near] ** 2  # [m] each point's depth error
        below = (residual < -(BELOW_MARGIN + 3.0 * sigma[:, None])).sum(axis=0)
        supported = support >= cfg.min_ground_points
        if not supported.any():
            return None
        fewest = below[supported].min()
        best = int(np.argmax(np.where(supported & (below == fewest), support, -1)))
        fit = normals[best], float(offsets[best])
        weights = 1.0 / (cfg.sigma_per_metre_squared * z ** 2 + 1e-3) ** 2
        threshold = 0.01
        for _ in range(3):
            residual = points @ fit[0] + fit[1]
            inliers = np.abs(residual) < threshold
            if inliers.sum() < cfg.min_ground_points:
                return None
            fit = _plane(points[inliers], weights[inliers])
            residual = points[inliers] @ fit[0] + fit[1]
            threshold = max(3.0 * 1.4826 * float(np.median(np.abs(residual))), 0.004)
        normal, offset = fit
        residual = points[inliers] @ normal + offset
        std = float(np.std(residual)) / math.sqrt(inliers.sum())
        return normal, offset, std

    def _edge(self, flat: np.ndarray, sigma: np.ndarray):
        """
        Fit the nearest edge to the raised points ``flat`` (ground x, y).

        Returns (x0 [m], slope [1] of x = x0 + slope * y, covariance of both, the riser
        points' mask) or None.
        """
        cfg = self.config
        # The nearest raised point in each 3 cm strip across the view.
        strip = np.floor(flat[:, 1] / 0.03).astype(int)
        order = np.lexsort((flat[:, 0], strip))
        first = np.ones(len(order), dtype=bool)
        first[1:] = strip[order][1:] != strip[order][:-1]
        nearest = order[first]
        if len(nearest) < 3:
            return None
        # A line through the strips' nearest points (the most points within a band), then
        # weighted least squares on every raised point near it.
        best = None
        candidates = flat[nearest]
        for i in range(len(candidates)):
            for j in range(i + 1, len(candidates), max(1, len(candidates) // 12)):
                dy = candidates[j, 1] - candidates[i, 1]
                if abs(dy) < 0.05:
                    continue
                slope = (candidates[j, 0] - candidates[i, 0]) / dy
                if abs(slope) > 1.0:
                    continue
                x0 = candidates[i, 0] - slope * candidates[i, 1]
                count = int(np.sum(np.abs(candidates[:, 0] - x0 - slope * candidates[:, 1])
                                   < 0.03))
                # Most support; of equal support, the nearer line.
                key = (count, -x0)
                if best is None or key > best[0]:
                    best = (key, x0, slope)
        if best is None:
            return None
        _, x0, slope = best
        # Past the line, only as far as a riser point's depth error reaches: further, the
        # top face's points, which would draw the line onto the top (by 1.3-1.6 cm for a
        # 2 cm riser, whose raised part is a few pixels high).
        beyond = np.minimum(RISER_BAND / 2.0, RISER_SLACK + 3.0 * sigma)  # [m]
        for _ in range(3):
            residual = flat[:, 0] - x0 - slope * flat[:, 1]
            riser = (residual > -RISER_BAND / 2.0) & (residual < beyond)
            if riser.sum() < cfg.min_riser_points:
                return None
            weights = 1.0 / (sigma[riser] ** 2 + 1e-6)
            design = np.stack([np.ones(riser.sum()), flat[riser, 1]], axis=1)
            normal_matrix = design.T @ (design * weights[:, None])
            x0, slope = np.linalg.solve(normal_matrix, design.T @ (weights * flat[riser, 0]))
        residual = flat[riser, 0] - x0 - slope * flat[riser, 1]
        chi2 = float(np.sum(weights * residual ** 2)) / max(1, riser.sum() - 2)
        cov = np.linalg.inv(normal_matrix) * max(chi2, 1.0)
        # Only a line across the view: an edge seen over less than 10 cm is no step edge.
        if np.ptp(flat[riser, 1]) < 0.1:
            return None
        return float(x0), float(slope), cov, riser

    def _end_seen(self, x0: float, yaw: float, along: float, height: float,
                  origin: np.ndarray, normal: np.ndarray, x_axis: np.ndarray,
                  y_axis: np.ndarray, depth: np.ndarray) -> bool:
        """
        Tell whether the camera sees ground past the edge's end ``along`` [m] from the axis.

        The probe is the point on the edge line there, half the step's height up: were the
        step to go on, the camera would see its riser there; if the pixel looking at it sees
        something farther, the step ends before it.
        """
        k, mount = self.intrinsics, self.mount
        on_line = np.array([x0 - along * math.sin(yaw), along * math.cos(yaw)])
        probe = (origin + on_line[0] * x_axis + on_line[1] * y_axis
                 + normal * (height / 2.0))  # [m] base_link
        in_camera = mount.rotation.T @ (probe - mount.position)
        if in_camera[2] <= 0.0:
            return False
        u = k.cx + k.fx * in_camera[0] / in_camera[2]
        v = k.cy + k.fy * in_camera[1] / in_camera[2]
        col, row = int(round(u)), int(round(v))
        if not (1 <= col < k.width - 1 and 1 <= row < k.height - 1):
            return False
        patch = depth[row - 1:row + 2, col - 1:col + 2]
        seen = patch[np.isfinite(patch)]
        margin = 3.0 * self.config.sigma_per_metre_squared * in_camera[2] ** 2 + 0.02
        return bool(seen.size > 0 and float(np.median(seen)) > in_camera[2] + margin)


def _plane(points: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, float]:
    """Weighted least-squares plane z = a x + b y + c as (upward unit normal, offset)."""
    design = np.stack([points[:, 0], points[:, 1], np.ones(len(points))], axis=1)
    a, b, c = np.linalg.solve(design.T @ (design * weights[:, None]),
                              design.T @ (weights * points[:, 2]))
    normal = np.array([-a, -b, 1.0])
    norm = float(np.linalg.norm(normal))
    return normal / norm, -c / norm


def _robust_mean(values: np.ndarray, sigma: np.ndarray) -> tuple[float, float]:
    """Mean of ``values`` within three robust spreads of their median, and its std."""
    centre = float(np.median(values))
    spread = max(1.4826 * float(np.median(np.abs(values - centre))), 1e-3)
    keep = np.abs(values - centre) < 3.0 * spread
    kept = values[keep]
    return float(np.mean(kept)), float(np.std(kept)) / math.sqrt(max(1, kept.size))
