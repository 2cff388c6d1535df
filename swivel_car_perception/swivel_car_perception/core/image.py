"""A depth image message's fields to metres, refused in one line when they do not fit; ROS-free."""

from __future__ import annotations

import numpy as np

from swivel_car_perception.core.detector import Intrinsics

# REP 118: 32FC1 in metres (NaN: no return), 16UC1 in millimetres (0: no return).
ENCODINGS = {'32FC1': (np.float32, 4, 1.0), '16UC1': (np.uint16, 2, 1e-3)}


def intrinsics_from_camera_info(width: int, height: int, k) -> Intrinsics:
    """
    Return the pinhole intrinsics of a CameraInfo's ``width``, ``height`` [px] and ``k``.

    Raises
    ------
    ValueError
        A zero size or a camera matrix that is not a pinhole's (one line).

    """
    k = [float(v) for v in k]
    if width < 2 or height < 2:
        raise ValueError(f'camera_info has no image size ({width}x{height})')
    if len(k) != 9 or not np.all(np.isfinite(k)) or k[0] <= 0.0 or k[4] <= 0.0:
        raise ValueError(f'camera_info k is not a camera matrix: {k}')
    return Intrinsics(width, height, k[0], k[4], k[2], k[5])


def depth_from_fields(encoding: str, width: int, height: int, step: int, is_bigendian: int,
                      data: bytes, intrinsics: Intrinsics) -> np.ndarray:
    """
    Return the depth [m] (height x width float64, NaN: no return) of an Image's fields.

    Raises
    ------
    ValueError
        An encoding other than 32FC1 or 16UC1, a size other than camera_info's, or data
        that does not fill the image (one line).

    """
    if encoding not in ENCODINGS:
        kinds = ' or '.join(ENCODINGS)
        raise ValueError(f'depth image encoding {encoding!r} is not a depth encoding '
                         f'({kinds}, REP 118)')
    if (width, height) != (intrinsics.width, intrinsics.height):
        raise ValueError(f'depth image is {width}x{height} but its camera_info says '
                         f'{intrinsics.width}x{intrinsics.height}')
    kind, size, scale = ENCODINGS[encoding]
    if step < width * size or len(data) < step * height:
        raise ValueError(f'depth image data ({len(data)} bytes, step {step}) does not fill '
                         f'{width}x{height} {encoding}')
    dtype = np.dtype(kind).newbyteorder('>' if is_bigendian else '<')
    rows = np.frombuffer(data, dtype=np.uint8, count=step * height).reshape(height, step)
    depth = rows[:, :width * size].copy().view(dtype).reshape(height, width)
    metres = depth.astype(np.float64) * scale
    if encoding == '16UC1':
        metres[depth == 0] = np.nan
    return metres
