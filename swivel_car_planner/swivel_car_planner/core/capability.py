"""
What the whole car climbs, as measured in physics: the planner's capability table.

The model says how high the *front* wheels can be lifted (thesis eq. 68 and the tip-over rule);
whether the rear axle follows depends on mass layout, drive train, friction and speed, which
the kinematics leave out. So the planner's whole-car limit is a measurement: the climbing
benchmark (``python -m swivel_car_studies.climb_benchmark --write-capability``) climbs randomised
steps in the real sim and writes this table; the planner refuses steps above the highest
height that succeeded reliably, and says so.

A height counts as climbed reliably when the lower one-sided ``confidence`` bound on its
success rate (Clopper-Pearson: the exact binomial bound) is at least ``reliable``: 40 trials
with 38 successes bound the rate at 0.86 with 90 % confidence, 8 of 8 only at 0.75. A table
without ``confidence`` compares the measured rate itself with ``reliable``.

File format (YAML)::

    reliable: 0.85           # success rate that counts as reliable [1]
    confidence: 0.9          # one-sided confidence of the bound on it [1]
    description: {...}       # the CarDescription the table was measured on
    command: ...             # how it was made
    heights: [0.02, ...]     # [m]
    trials: [8, ...]         # climbs per height
    successes: [8, ...]      # climbs with all four wheels on top
"""

from __future__ import annotations

from dataclasses import dataclass, fields
import math
from pathlib import Path
from typing import Any

from scipy.special import betaincinv
from swivel_car_model.description import CarDescription
import yaml

RELIABLE = 0.9  # [1] success rate that counts as "climbs reliably" (measured rate)
BOUND_RELIABLE = 0.85  # [1] the same, for the lower confidence bound on the rate
CONFIDENCE = 0.9  # [1] one-sided confidence of that bound
INSTALLED = 'installed'  # the table shipped in the package's share/config/capability.yaml
NONE = 'none'  # no table: only the model's limits


@dataclass(frozen=True)
class CapabilityTable:
    """
    Whole-car climbing success by step height for one robot description.

    Raises
    ------
    ValueError
        Inconsistent lists, unsorted or non-positive heights, successes above trials.

    """

    heights: tuple[float, ...]  # [m], increasing
    trials: tuple[int, ...]
    successes: tuple[int, ...]
    description: dict[str, Any]
    reliable: float = RELIABLE  # [1]
    command: str = ''
    confidence: float | None = None  # [1] None: the measured rate is compared, not a bound

    def __post_init__(self) -> None:
        if not len(self.heights) == len(self.trials) == len(self.successes):
            raise ValueError('heights, trials and successes must have the same length')
        if any(not math.isfinite(h) or h <= 0.0 for h in self.heights) \
                or list(self.heights) != sorted(set(self.heights)):
            raise ValueError(f'heights must be positive and increasing, got {self.heights}')
        if any(t < 1 or not 0 <= s <= t for t, s in zip(self.trials, self.successes)):
            raise ValueError('every height needs trials >= 1 and 0 <= successes <= trials')
        if not 0.0 < self.reliable <= 1.0:
            raise ValueError(f'reliable must be in (0, 1], got {self.reliable!r}')
        if self.confidence is not None and not 0.0 < self.confidence < 1.0:
            raise ValueError(f'confidence must be in (0, 1), got {self.confidence!r}')

    @property
    def rates(self) -> dict[float, float]:
        """Success rate by height {[m]: [1]}."""
        return {h: s / t for h, t, s in zip(self.heights, self.trials, self.successes)}

    @property
    def lower_bounds(self) -> dict[float, float]:
        """
        Lower one-sided ``confidence`` bound on the success rate by height {[m]: [1]}.

        Clopper-Pearson; the measured rates when the table has no ``confidence``.
        """
        if self.confidence is None:
            return self.rates
        return {h: lower_bound(s, t, self.confidence)
                for h, t, s in zip(self.heights, self.trials, self.successes)}

    @property
    def limit(self) -> float:
        """
        Highest height of the unbroken run of reliable heights from the lowest [m].

        Reliable: ``lower_bounds`` at least ``reliable``. 0 when even the lowest is not.
        """
        best = 0.0
        for height, rate in self.lower_bounds.items():
            if rate < self.reliable:
                break
            best = height
        return best

    def matches(self, description: CarDescription) -> bool:
        """Tell whether the table was measured on this robot."""
        return self.description == description_values(description)

    @classmethod
    def load(cls, path: str | Path) -> 'CapabilityTable':
        """
        Read a table file.

        Raises
        ------
        ValueError
            The file is missing, not YAML or not a valid table; the message names the file.

        """
        try:
            data = yaml.safe_load(Path(path).read_text())
            return cls(heights=tuple(float(h) for h in data['heights']),
                       trials=tuple(int(t) for t in data['trials']),
                       successes=tuple(int(s) for s in data['successes']),
                       description=dict(data['description']),
                       reliable=float(data.get('reliable', RELIABLE)),
                       command=str(data.get('command', '')),
                       confidence=(None if data.get('confidence') is None
                                   else float(data['confidence'])))
        except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError) as error:
            raise ValueError(f'capability table {path}: {error}') from error

    def save(self, path: str | Path, header: str = '') -> None:
        """Write the table (with an optional comment ``header``)."""
        data = {'reliable': self.reliable,
                **({} if self.confidence is None else {'confidence': self.confidence}),
                'command': self.command,
                'description': self.description, 'heights': list(self.heights),
                'trials': list(self.trials), 'successes': list(self.successes)}
        comment = ''.join(f'# {line}\n' for line in header.splitlines())
        Path(path).write_text(comment + yaml.safe_dump(data, sort_keys=False))


def lower_bound(successes: int, trials: int, confidence: float) -> float:
    """
    Return the lower one-sided Clopper-Pearson bound on a success rate [1].

    ``successes`` of ``trials`` succeeded; the true rate is at least the bound with
    probability ``confidence``.
    """
    if successes == 0:
        return 0.0
    # The (1 - confidence) quantile of Beta(successes, trials - successes + 1), from
    # scipy.special: scipy.stats would add a quarter of a second of CPU to every planner start.
    return float(betaincinv(successes, trials - successes + 1, 1.0 - confidence))


def description_values(description: CarDescription) -> dict[str, Any]:
    """Return the description's fields as plain values (what a table records)."""
    return {item.name: getattr(description, item.name) for item in fields(description)}


def table_for(value: str) -> tuple[CapabilityTable | None, str]:
    """
    Return the table a ``capability_file`` parameter names, and its path.

    The parameter is ``INSTALLED`` (the package's), ``NONE`` (no table: None) or a file path.

    Raises
    ------
    ValueError
        The file cannot be read as a table; the message names it.

    """
    if value == NONE:
        return None, ''
    if value == INSTALLED:
        from ament_index_python.packages import get_package_share_directory
        value = str(Path(get_package_share_directory('swivel_car_planner'))
                    / 'config' / 'capability.yaml')
    return CapabilityTable.load(value), value
