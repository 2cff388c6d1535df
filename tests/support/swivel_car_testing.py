"""Helpers for tests that run the real nodes: isolated ROS domains, node processes
started the way `ros2 run` starts them (from scripts/swivel_car_stack.py), and spinning
until a condition holds.

Import from any test (the root pytest.ini puts tests/support and scripts on sys.path).
"""

from __future__ import annotations

import itertools
import os

from swivel_car_stack import (  # noqa: F401  (re-exported for the tests)
    INSTALL_DIR, REPO_ROOT, NodeProcess, config_path, executable_path, lockstep_parameters,
    ros_environment, spin_until, start_node)

# Each test run of real nodes gets its own ROS domain, so parallel runs and earlier tests'
# stragglers are never heard. The base spreads concurrent pytest processes apart.
_DOMAIN_BASE = 1 + (os.getpid() % 23) * 10  # ROS_DOMAIN_ID 1 .. 230
_DOMAIN_IDS = itertools.cycle(range(_DOMAIN_BASE, _DOMAIN_BASE + 10))


def next_domain_id() -> int:
    """A ROS_DOMAIN_ID not used by the previous nine calls in this process."""
    return next(_DOMAIN_IDS)

