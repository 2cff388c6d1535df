"""Value and slew-rate limiting of one signal (velocities, the swivel set point)."""

from __future__ import annotations

import math

from swivel_car_model.checks import check_finite_number, check_number


class SlewLimiter:
    """
    Clamps a signal to ``+-max_value`` and its rate of change to ``max_rate``.

    Parameters
    ----------
    max_value : float
        Largest |output|, > 0 (inf: no clamp). # [unit]
    max_rate : float
        Largest |d output / dt|, > 0 (inf: no rate limit). # [unit/s]
    initial : float
        Starting output. # [unit]

    """

    def __init__(self, max_value: float, max_rate: float, initial: float = 0.0) -> None:
        check_number('max_value', max_value, above=0.0, allow_inf=True)
        check_number('max_rate', max_rate, above=0.0, allow_inf=True)
        self.max_value = max_value
        self.max_rate = max_rate
        self.value = self._clamp('initial', initial)

    def _clamp(self, name: str, value: float) -> float:
        check_finite_number(name, value)
        return max(-self.max_value, min(self.max_value, value))

    def reset(self, value: float) -> None:
        """Jump to ``value`` (clamped), e.g. to the measured state."""
        self.value = self._clamp('value', value)

    def step(self, target: float, dt: float, max_rate: float | None = None) -> float:
        """
        Move towards ``target`` for ``dt`` seconds; returns the new output.

        ``max_rate`` overrides the configured rate for this step (e.g. a planner's move rate).
        """
        target = self._clamp('target', target)
        check_finite_number('dt', dt)
        if dt < 0.0:
            raise ValueError(f'dt must be >= 0, got {dt!r}')
        if max_rate is not None:
            check_number('max_rate', max_rate, at_least=0.0, allow_inf=True)
        rate = self.max_rate if max_rate is None else min(max_rate, self.max_rate)
        step = rate * dt if dt > 0.0 else 0.0
        self.value += max(-step, min(step, target - self.value))
        return self.value


def steering_speed_scale(error: float, full_below: float, stop_above: float) -> float:
    """
    Drive speed factor while the swivel is away from its target.

    1 for ``|error| <= full_below``, ``cos(error)`` up to ``stop_above``, 0 beyond (as
    ros2_controllers' tricycle_controller, which keeps 0.01 there; we stop).

    Parameters
    ----------
    error : float
        Swivel target minus measured angle. # [rad]
    full_below, stop_above : float
        Thresholds, ``0 <= full_below <= stop_above <= pi/2``. # [rad]

    """
    magnitude = abs(error)
    if magnitude <= full_below:
        return 1.0
    if magnitude <= stop_above:
        return math.cos(magnitude)
    return 0.0
