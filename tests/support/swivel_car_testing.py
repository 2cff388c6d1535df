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

# Each test run of real nodes gets its own ROS domain, so that earlier tests' stragglers are
# never heard: a cycle of DOMAINS_PER_WORKER ids per process. pytest-xdist workers (make test
# runs several) get disjoint cycles by their worker index, so two workers never share a
# domain; concurrent pytest runs on one machine are spread apart by the run's process id (the
# controlling pytest's, which is a worker's parent). ROS_DOMAIN_ID 1 .. 230 on Linux.
DOMAINS_PER_WORKER = 10
_MAX_DOMAIN_ID = 230


def worker_domain_ids(worker: str | None, worker_count: int, run_id: int) -> range:
    """The ROS_DOMAIN_IDs of one pytest process: ``worker`` is PYTEST_XDIST_WORKER ('gw0',
    'gw1', ...; None without xdist), ``worker_count`` PYTEST_XDIST_WORKER_COUNT, ``run_id``
    the controlling pytest's process id. Disjoint for the workers of one run."""
    index = int(worker.removeprefix('gw')) if worker else 0
    workers = max(worker_count, index + 1)
    span = workers * DOMAINS_PER_WORKER  # ids of one run
    if span > _MAX_DOMAIN_ID:
        raise RuntimeError(f'{workers} pytest-xdist workers need {span} ROS domains, more than '
                           f'the {_MAX_DOMAIN_ID} there are')
    base = 1 + (run_id % (_MAX_DOMAIN_ID // span)) * span + index * DOMAINS_PER_WORKER
    return range(base, base + DOMAINS_PER_WORKER)


_WORKER = os.environ.get('PYTEST_XDIST_WORKER')
DOMAIN_IDS = worker_domain_ids(_WORKER, int(os.environ.get('PYTEST_XDIST_WORKER_COUNT', '1')),
                               os.getppid() if _WORKER else os.getpid())
_DOMAIN_IDS = itertools.cycle(DOMAIN_IDS)
# Anything that initialises rclpy without a domain (scripts/node_docs.py) stays on this
# process's first domain, and every node is heard on this host only.
os.environ['ROS_DOMAIN_ID'] = str(DOMAIN_IDS[0])
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'


def next_domain_id() -> int:
    """A ROS_DOMAIN_ID of this pytest process (worker) not used by its previous
    DOMAINS_PER_WORKER - 1 calls; no other worker of this run uses it."""
    return next(_DOMAIN_IDS)
