"""Input checks shared by every configuration of the stack."""

from __future__ import annotations

import math
from typing import Any


def check_finite_number(name: str, value: Any) -> None:
    """
    Refuse anything but a finite int or float (a bool is not a number here).

    Raises
    ------
    ValueError
        Naming ``name``.

    """
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f'{name} must be a finite number, got {value!r}')
