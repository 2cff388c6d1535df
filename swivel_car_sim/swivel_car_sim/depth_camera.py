"""
The sim's depth camera: a RealSense D435-class stereo camera on the car's body; ROS-free.

pybullet's tiny renderer draws the depth buffer (``getCameraImage``), which gives metres along
the optical axis as ``far * near / (far - (far - near) * d)``. Measured on this machine with
the car and a step in view (``DepthCamera.true_depth`` against ``rayTestBatch`` through the
same pixels): the render took 8 ms per 212 x 120 frame, the ray casts 90 ms (three batches of
at most 8192 rays; a batch of 16384 returns nothing); both agreed to 0.12 mm (95th
percentile) away from object borders with the intrinsics ``Intrinsics.of`` gives
(cx = W/2, cy = H/2 - 1 in 0-based pixels; the textbook (W-1)/2, (H-1)/2 was off by 7 mm
in the median). So the camera renders. It sees the car's own parts as a real camera on the
body would (the front column, axle and wheels at the bottom of the image).

The camera sits where ``CarDescription.camera_mount`` puts it (the URDF's ``camera_link``);
the image is in its REP-103 optical frame (z forward, x right, y down). The reading's noise
is ``sensor_models.StereoDepthNoise``.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
import pybullet

from swivel_car_model.description import CarDescription
from swivel_car_sim.sensor_models import StereoDepthNoise

VERTICAL_FOV = 58.0  # [deg] D435 depth field of view, 87 x 58 deg at 848 x 480
NEAR_CLIP = 0.05  # [m] render's near plane, below the camera's minimum range
# name -> (default, description): the sim node's camera parameters.
PARAMETERS: dict[str, tuple[object, str]] = {
    'camera_rate': (10.0, '[Hz] depth camera frame rate (sim time); control_period divided '
                          'by a whole number; 0 turns the camera off (campaigns, benchmarks)'),
    'camera_width': (212, '[px] depth image width: the D435 848 decimated by 4 (the '
                          'height sets the 58 deg vertical view, the aspect the horizontal)'),
    'camera_height': (120, '[px] depth image height: the D435 480 decimated by 4'),
    'camera_noise': (True, 'D435 stereo depth noise, dropouts and range limits '
                           '(sensor_models.StereoDepthNoise); false: exact depth'),
    'camera_seed': (0, 'seed of the depth noise; each frame draws from the seed and its stamp'),
    'camera_frame_id': ('camera_depth_optical_frame',
                        'frame of the depth image and camera_info (REP 103 optical: z '
                        'forward, x right, y down)'),
}
MAX_PIXELS = 848 * 480  # the native image


@dataclass(frozen=True)
class CameraConfig:
    """The camera's parameters, validated (see ``PARAMETERS``)."""

    rate: float  # [Hz]; 0: off
    width: int  # [px]
    height: int  # [px]
    noise: bool
    seed: int
    frame_id: str

    @classmethod
    def from_values(cls, values: dict[str, object], control_period: float) -> 'CameraConfig':
        """
        Validate the parameter values against the sim's ``control_period`` [s].

        Raises
        ------
        ValueError
            A value of the wrong type or out of range; one line naming it.

        """
        rate, width, height = values['camera_rate'], values['camera_width'], \
            values['camera_height']
        if isinstance(rate, bool) or not isinstance(rate, (int, float)) \
                or not math.isfinite(rate) or rate < 0.0:
            raise ValueError(f'camera_rate must be a number >= 0 [Hz], got {rate!r}')
        if rate > 0.0:
            every = 1.0 / (rate * control_period)
            if round(every) < 1 or abs(every - round(every)) > 1e-9:
                raise ValueError(f'camera_rate must divide the control rate '
                                 f'({1.0 / control_period:g} Hz) by a whole number, got {rate!r}')
        for name, value in (('camera_width', width), ('camera_height', height)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 2:
                raise ValueError(f'{name} must be an integer >= 2 [px], got {value!r}')
        if width * height > MAX_PIXELS:
            raise ValueError(f'camera_width x camera_height must be at most the native '
                             f'848 x 480 pixels, got {width} x {height}')
        if not isinstance(values['camera_noise'], bool):
            raise ValueError(f"camera_noise must be a bool, got {values['camera_noise']!r}")
        seed = values['camera_seed']
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise ValueError(f'camera_seed must be an integer >= 0, got {seed!r}')
        frame_id = values['camera_frame_id']
        if not isinstance(frame_id, str) or not frame_id:
            raise ValueError(f'camera_frame_id must be a frame name, got {frame_id!r}')
        return cls(float(rate), width, height, values['camera_noise'], seed, frame_id)

    def periods_per_frame(self, control_period: float) -> int:
        """Control periods from one frame to the next (the rate is > 0)."""
        return round(1.0 / (self.rate * control_period))


@dataclass(frozen=True)
class Intrinsics:
    """
    A pinhole camera without distortion: image size and the projection, 0-based pixels.

    Attributes
    ----------
    width, height : int  # [px]
    fx, fy : float  # [px] focal lengths
    cx, cy : float  # [px] principal point

    """

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def of(cls, width: int, height: int) -> 'Intrinsics':
        """Return the intrinsics of the tiny renderer's ``width`` x ``height`` image."""
        f = (height / 2.0) / math.tan(math.radians(VERTICAL_FOV) / 2.0)  # [px]
        return cls(width, height, f, f, width / 2.0, height / 2.0 - 1.0)

    @property
    def k(self) -> list[float]:
        """Return the 3x3 camera matrix, row-major, as CameraInfo.k."""
        return [self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0]


class DepthCamera:
    """
    Render depth images from the camera on the car.

    Parameters
    ----------
    client : int
        The pybullet physics client of the world.
    description : CarDescription
        Where the camera sits (``camera_mount``).
    width, height : int
        Image size. # [px]
    noise : StereoDepthNoise or None
        The reading's error; None: exact depth.
    seed : int
        Each frame's noise comes from ``numpy.random.default_rng([seed, stamp])``: the same
        stamp gives the same frame, whatever frames were taken before.

    """

    def __init__(self, client: int, description: CarDescription, width: int, height: int,
                 noise: StereoDepthNoise | None = StereoDepthNoise(), seed: int = 0) -> None:
        self._client = client
        self.intrinsics = Intrinsics.of(width, height)
        # The optical centre [m] and axes (columns x right, y down, z forward) in base_link.
        self._mount_position, self.optical_in_base = description.camera_optical_pose()
        self.noise = noise
        self._seed = seed
        self._far = noise.max_range if noise is not None else StereoDepthNoise().max_range
        self._projection = pybullet.computeProjectionMatrixFOV(
            fov=VERTICAL_FOV, aspect=width / height, nearVal=NEAR_CLIP, farVal=self._far)

    def optical_pose(self, base_position: np.ndarray, base_orientation: np.ndarray) -> tuple[
            np.ndarray, np.ndarray]:
        """Return the optical frame's origin [m] and axes (columns) in the world."""
        rotation = np.array(pybullet.getMatrixFromQuaternion(
            [float(q) for q in base_orientation])).reshape(3, 3)
        return (np.asarray(base_position, dtype=float) + rotation @ self._mount_position,
                rotation @ self.optical_in_base)

    def true_depth(self, base_position: np.ndarray,
                   base_orientation: np.ndarray) -> np.ndarray:
        """Exact depth [m] along the optical axis (height x width), NaN where nothing is."""
        eye, axes = self.optical_pose(base_position, base_orientation)
        view = pybullet.computeViewMatrix(eye.tolist(), (eye + axes[:, 2]).tolist(),
                                          (-axes[:, 1]).tolist())
        width, height = self.intrinsics.width, self.intrinsics.height
        buffer = pybullet.getCameraImage(
            width, height, view, self._projection, renderer=pybullet.ER_TINY_RENDERER,
            flags=pybullet.ER_NO_SEGMENTATION_MASK, physicsClientId=self._client)[3]
        d = np.reshape(np.asarray(buffer, dtype=np.float64), (height, width))
        near, far = NEAR_CLIP, self._far
        with np.errstate(divide='ignore'):
            depth = far * near / (far - (far - near) * d)
        # The far plane: nothing in range (the sky).
        return np.where(d < 1.0 - 1e-7, depth, np.nan)

    def capture(self, base_position: np.ndarray, base_orientation: np.ndarray,
                stamp: int) -> np.ndarray:
        """
        Return the frame at ``stamp`` [ns]: float32 [m] (height x width), NaN: no return.

        ``base_position`` [m] and ``base_orientation`` (x, y, z, w) are base_link's in the
        world.
        """
        depth = self.true_depth(base_position, base_orientation)
        if self.noise is None:
            return depth.astype(np.float32)
        return self.noise.apply(depth, np.random.default_rng([self._seed, stamp]))
