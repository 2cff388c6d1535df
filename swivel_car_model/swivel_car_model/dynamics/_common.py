"""Checks and constants shared by the dynamics models."""

from __future__ import annotations

import math

from swivel_car_model.params import SwivelCarParams

GRAVITY = 9.81  # [m/s^2]
PROFILE_SIZE = 2001  # samples of the cached kinematic profiles over [0, max_swivel_angle]


def finite(name: str, value: float) -> float:
    """Return ``value`` as a float; ValueError naming ``name`` if it is not finite."""
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f'{name} must be finite, got {value!r}')
    return value


def positive(name: str, value: float) -> float:
    """Return ``value`` as a float; ValueError naming ``name`` unless finite and > 0."""
    if finite(name, value) <= 0.0:
        raise ValueError(f'{name} must be > 0, got {value!r}')
    return float(value)


def swivel_angle(p: SwivelCarParams, name: str, value: float) -> float:
    """Return ``value`` as a float; ValueError naming ``name`` beyond +-max_swivel_angle."""
    value = finite(name, value)
    if abs(value) > p.max_swivel_angle + 1e-12:
        raise ValueError(
            f'{name} must be within +-max_swivel_angle = {p.max_swivel_angle!r} rad, '
            f'got {value!r}')
    return value
