"""
Hypothesis strategies of bad inputs, and the check of a refusal, for the cores' tests.

Every ROS-free core refuses a bad input with one ValueError whose message names the field
and changes nothing (issue 12). Import from any test (pytest.ini puts tests/support on
sys.path).
"""

from __future__ import annotations

import math
import re

from hypothesis import strategies as st

NON_FINITE = st.sampled_from([math.nan, math.inf, -math.inf])
# What a YAML file or a parameter of the wrong type hands over where a number is due.
NOT_NUMERIC = st.sampled_from(['1.0', 'heavy', None, [1.0], {'x': 1.0}])
NOT_A_FINITE_NUMBER = NON_FINITE | NOT_NUMERIC | st.booleans()


def at_most(bound: float) -> st.SearchStrategy[float]:
    """Return finite floats <= ``bound`` (out of range of a field that must be above it)."""
    return st.floats(max_value=bound, allow_nan=False, allow_infinity=False)


def at_least(bound: float) -> st.SearchStrategy[float]:
    """Return finite floats >= ``bound`` (out of range of a field that must be below it)."""
    return st.floats(min_value=bound, allow_nan=False, allow_infinity=False)


def assert_refusal_names(error: BaseException, field: str) -> None:
    """Assert that ``error`` is one clear line that names ``field``."""
    message = str(error)
    assert isinstance(error, ValueError), repr(error)
    assert '\n' not in message and 'Traceback' not in message, message
    assert re.search(rf'(?<![\w.]){re.escape(field)}(?!\w)', message), (field, message)
