"""Reading named joints from JointState-like data, ROS-free (plain lists in, floats out)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence


@dataclass(frozen=True)
class JointSample:
    """Position [rad] and rate [rad/s] of one joint at one time."""

    position: float
    rate: float


class MissingJointError(ValueError):
    """A wanted joint is absent from the message or has no usable data."""


class JointReader:
    """Extracts wanted joints by name; fills in a missing or non-finite velocity from the
    change of position since the previous sample, unwrapping continuous joints (wheels)
    whose positions a driver may report wrapped to (-pi, pi].

    Parameters
    ----------
    names : sequence of str
        Joints to read.
    """

    def __init__(self, names: Sequence[str]) -> None:
        self.names = tuple(names)
        self._previous: dict[str, tuple[float, float]] = {}  # name -> (time [s], position)

    def reset(self) -> None:
        """Forget previous positions (e.g. after time jumped back)."""
        self._previous.clear()

    def read(self, t: float, names: Sequence[str], positions: Sequence[float],
             velocities: Sequence[float]) -> dict[str, JointSample]:
        """Samples of the wanted joints at time ``t`` [s].

        Raises
        ------
        MissingJointError
            A wanted joint is absent or its position is not finite (nothing is remembered), or
            it has no velocity and no earlier sample to difference against (its position is
            remembered for the next message).
        """
        index = {name: i for i, name in enumerate(names)}
        positions_now: dict[str, float] = {}
        rates_now: dict[str, float] = {}
        for name in self.names:
            i = index.get(name)
            if i is None or i >= len(positions) or not math.isfinite(positions[i]):
                raise MissingJointError(f'joint {name!r} missing or without a finite position')
            positions_now[name] = float(positions[i])
            rates_now[name] = float(velocities[i]) if i < len(velocities) else math.nan
        samples: dict[str, JointSample] = {}
        for name, position in positions_now.items():
            rate = rates_now[name]
            if not math.isfinite(rate):
                previous = self._previous.get(name)
                if previous is None or t <= previous[0]:
                    rate = math.nan
                else:
                    step = math.remainder(position - previous[1], 2.0 * math.pi)
                    rate = step / (t - previous[0])
            samples[name] = JointSample(position, rate)
        # Positions are kept even when a rate is missing, so the next message can difference.
        for name, position in positions_now.items():
            self._previous[name] = (t, position)
        missing = [name for name, sample in samples.items() if not math.isfinite(sample.rate)]
        if missing:
            raise MissingJointError(f'joints {missing} have no velocity and no earlier position '
                                    'to difference against')
        return samples
