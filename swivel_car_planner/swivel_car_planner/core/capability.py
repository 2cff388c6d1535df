"""
What the whole car climbs, as measured in physics: the planner's capability table.

The model says how high the *front* wheels can be lifted (thesis eq. 68 and the tip-over rule);
whether the rear axle follows depends on mass layout, drive train, friction and speed, which
the kinematics leave out. So the planner's whole-car limit is a measurement: the climbing
benchmark (``python -m swivel_car_bringup.climb_benchmark --write-capability``) climbs randomised
steps in the real sim and writes this table; the planner refuses steps above the highest
height that succeeded reliably, and says so.

File format (YAML)::

    reliable: 0.9            # success rate that counts as reliable [1]
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

from swivel_car_model.description import CarDescription
import yaml

RELIABLE = 0.9  # [1] success rate that counts as "climbs reliably"
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

    @property
    def rates(self) -> dict[float, float]:
        """Success rate by height {[m]: [1]}."""
        return {h: s / t for h, t, s in zip(self.heights, self.trials, self.successes)}

    @property
    def limit(self) -> float:
        """
        Highest height of the unbroken run of reliable heights from the lowest [m].

        0 when even the lowest is not reliable.
        """
        best = 0.0
        for height, rate in self.rates.items():
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
                       command=str(data.get('command', '')))
        except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError) as error:
            raise ValueError(f'capability table {path}: {error}') from error

    def save(self, path: str | Path, header: str = '') -> None:
        """Write the table (with an optional comment ``header``)."""
        data = {'reliable': self.reliable, 'command': self.command,
                'description': self.description, 'heights': list(self.heights),
                'trials': list(self.trials), 'successes': list(self.successes)}
        comment = ''.join(f'# {line}\n' for line in header.splitlines())
        Path(path).write_text(comment + yaml.safe_dump(data, sort_keys=False))


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
