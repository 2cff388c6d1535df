"""Synthetic depth images for the detector's tests: flat ground and a box step, ray cast."""

from __future__ import annotations

import math

import numpy as np
from swivel_car_model.description import CarDescription
from swivel_car_perception.core.detector import Intrinsics, Mount

DESCRIPTION = CarDescription()
MOUNT = Mount.of(DESCRIPTION)
# The sim camera's default image: the D435's 848 x 480 decimated by 4, 58 deg high.
FOCAL = 60.0 / math.tan(math.radians(29.0))  # [px]
INTRINSICS = Intrinsics(212, 120, FOCAL, FOCAL, 106.0, 59.0)
SIGMA_PER_METRE_SQUARED = 0.08 / (424.0 * 0.05)  # [1/m] D435 stereo RMS error / depth^2


def depth_image(step=None, noise_seed=None, mount=MOUNT, intrinsics=INTRINSICS,
                dropout=0.01):
    """
    Return a depth image [m] of flat ground and optionally one box step.

    ``step`` is (height, distance, yaw, width, offset, depth) as StepObstacle and ClimbStep
    state them [m, m, rad, m, m, m]. With ``noise_seed`` the D435's noise and dropouts.
    """
    k = intrinsics
    v, u = np.mgrid[0:k.height, 0:k.width]
    rays = np.stack([(u - k.cx) / k.fx, (v - k.cy) / k.fy, np.ones(u.shape)], axis=-1)
    rays = rays.reshape(-1, 3) @ mount.rotation.T  # base_link, unit optical depth
    origin = mount.position
    ground_z = -mount.ground_height
    with np.errstate(divide='ignore', invalid='ignore'):
        depth = np.where(rays[:, 2] < 0.0, (ground_z - origin[2]) / rays[:, 2], np.inf)
        if step is not None:
            height, distance, yaw, width, offset, box_depth = step
            edge = np.array([mount.front_axle + distance, 0.0, ground_z])
            axes = np.array([[math.cos(yaw), math.sin(yaw), 0.0],
                             [-math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
            o = axes @ (origin - edge)
            d = rays @ axes.T
            low = np.array([0.0, offset - width / 2.0, 0.0])
            high = np.array([box_depth, offset + width / 2.0, height])
            t1, t2 = (low - o) / d, (high - o) / d
            near = np.nanmax(np.minimum(t1, t2), axis=1)
            far = np.nanmin(np.maximum(t1, t2), axis=1)
            hit = (near <= far) & (near > 0.0)
            depth = np.where(hit & (near < depth), near, depth)
    depth[~np.isfinite(depth) | (depth > 10.0)] = np.nan
    depth = depth.reshape(k.height, k.width)
    if noise_seed is not None:
        rng = np.random.default_rng(noise_seed)
        depth = depth + SIGMA_PER_METRE_SQUARED * depth ** 2 * rng.standard_normal(depth.shape)
        depth[rng.random(depth.shape) < dropout] = np.nan
    return depth
