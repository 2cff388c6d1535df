"""Input checks shared by every configuration of the stack."""

from __future__ import annotations

import math
from typing import Any


def check_number(name: str, value: Any, *, above: float | None = None,
                 at_least: float | None = None, unit: str = '',
                 allow_inf: bool = False) -> float:
    """
    Refuse anything but an int or float in range; return it as a float.

    Any wrong type gets the same one-line ValueError as a value out of range, never a
    TypeError from the comparison.

    Parameters
    ----------
    name : str
        What the message calls the value.
    value : Any
        An int or float; a bool is not a number here (``True > 0`` holds in Python).
    above, at_least : float, optional
        The value must be > ``above`` and >= ``at_least``.
    unit : str
        Unit of the bound, for the message (e.g. 'Hz').
    allow_inf : bool
        Take +-inf (within the bounds); NaN never.

    Raises
    ------
    ValueError
        ``<name> must be a finite number > 0 Hz, got 'x'``.

    """
    number = math.nan
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        try:
            number = float(value)
        except OverflowError:  # an int beyond float range
            pass
    if math.isnan(number) or (math.isinf(number) and not allow_inf) \
            or (above is not None and number <= above) \
            or (at_least is not None and number < at_least):
        bound = ''.join(f' {sign} {limit:g}' for sign, limit in (('>', above), ('>=', at_least))
                        if limit is not None)
        kind = 'number' if allow_inf else 'finite number'
        raise ValueError(f'{name} must be a {kind}{bound}{" " + unit if unit else ""}, '
                         f'got {value!r}')
    return number


def check_finite_number(name: str, value: Any) -> None:
    """
    Refuse anything but a finite int or float (a bool is not a number here).

    Raises
    ------
    ValueError
        Naming ``name``.

    """
    check_number(name, value)


def check_nonempty_string(name: str, value: Any) -> None:
    """
    Refuse anything but a non-empty str (a frame id, a joint name).

    Raises
    ------
    ValueError
        ``<name> must be a non-empty string``.

    """
    if not isinstance(value, str) or not value:
        raise ValueError(f'{name} must be a non-empty string')
