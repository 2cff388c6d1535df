"""Reading named joints from JointState-like data, ROS-free (plain lists in, floats out)."""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Sequence


@dataclass(frozen=True)
class JointSample:
    """Position [rad] and rate [rad/s] of one joint at one time."""

    position: float
    rate: float


class MissingJointError(ValueError):
    """A wanted joint is absent from the message or has no usable data."""


class JointReader:
    """
    A reader of wanted joints by name.

    It fills in a missing or non-finite velocity from the change of position since the
    previous sample, unwrapping continuous joints (wheels) whose positions a driver may
    report wrapped to (-pi, pi].

    Parameters
    ----------
    names : sequence of str
        Joints to read.

    """

    def __init__(self, names: Sequence[str]) -> None:
        self.names = tuple(names)
        self._previous: dict[str, tuple[float, float]] = {}  # name -> (time [s], position)
        # The message layout last seen and where the wanted joints sit in it: a driver sends
        # the same names in every message, so they are looked up once.
        self._layout: tuple[str, ...] | None = None
        self._indices: tuple[int | None, ...] = ()

    def reset(self) -> None:
        """Forget previous positions (e.g. after time jumped back)."""
        self._previous.clear()

    def read(self, t: float, names: Sequence[str], positions: Sequence[float],
             velocities: Sequence[float]) -> dict[str, JointSample]:
        """
        Return the samples of the wanted joints at time ``t`` [s].

        Raises
        ------
        MissingJointError
            A wanted joint is absent or its position is not finite (nothing is remembered), or
            it has no velocity and no earlier sample to difference against (its position is
            remembered for the next message).

        """
        layout = tuple(names)
        if layout != self._layout:
            index = {name: i for i, name in enumerate(layout)}
            self._indices = tuple(index.get(name) for name in self.names)
            self._layout = layout
        readings = []
        for name, i in zip(self.names, self._indices):
            if i is None or i >= len(positions) or not math.isfinite(positions[i]):
                raise MissingJointError(f'joint {name!r} missing or without a finite position')
            readings.append((name, float(positions[i]),
                             float(velocities[i]) if i < len(velocities) else math.nan))
        samples: dict[str, JointSample] = {}
        for name, position, rate in readings:
            if not math.isfinite(rate):
                previous = self._previous.get(name)
                if previous is None or t <= previous[0]:
                    rate = math.nan
                else:
                    step = math.remainder(position - previous[1], 2.0 * math.pi)
                    rate = step / (t - previous[0])
            samples[name] = JointSample(position, rate)
        # Positions are kept even when a rate is missing, so the next message can difference.
        for name, position, _ in readings:
            self._previous[name] = (t, position)
        missing = [name for name, sample in samples.items() if not math.isfinite(sample.rate)]
        if missing:
            raise MissingJointError(f'joints {missing} have no velocity and no earlier position '
                                    'to difference against')
        return samples
