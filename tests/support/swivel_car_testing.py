"""Helpers for tests that run the real nodes: isolated ROS domains, node processes
started the way `ros2 run` starts them (from scripts/swivel_car_stack.py), and spinning
until a condition holds.

Import from any test (the root pytest.ini puts tests/support and scripts on sys.path).
"""

from __future__ import annotations

import itertools
import os
import time
from typing import Any, Callable

from swivel_car_stack import (  # noqa: F401  (re-exported for the tests)
    INSTALL_DIR, REPO_ROOT, NodeProcess, config_path, executable_path, ros_environment)

# Each test run of real nodes gets its own ROS domain, so parallel runs and earlier tests'
# stragglers are never heard. The base spreads concurrent pytest processes apart.
_DOMAIN_BASE = 1 + (os.getpid() % 23) * 10  # ROS_DOMAIN_ID 1 .. 230
_DOMAIN_IDS = itertools.cycle(range(_DOMAIN_BASE, _DOMAIN_BASE + 10))


def next_domain_id() -> int:
    """A ROS_DOMAIN_ID not used by the previous nine calls in this process."""
    return next(_DOMAIN_IDS)


def spin_until(executor: Any, condition: Callable[[], bool], timeout: float,
               what: str = 'condition') -> None:
    """Spin ``executor`` until ``condition()`` holds; AssertionError after ``timeout``
    wall seconds (a guard against a hang, not a measurement)."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f'timed out after {timeout} s waiting for {what}')
        executor.spin_once(timeout_sec=0.05)
