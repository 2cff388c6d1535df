"""
Helpers for tests that run the real nodes.

Isolated ROS domains, node processes started the way `ros2 run` starts them (from
scripts/swivel_car_stack.py), and spinning until a condition holds.

Import from any test (the root pytest.ini puts tests/support and scripts on sys.path).
"""

from __future__ import annotations

import fcntl
import itertools
import os
from pathlib import Path
import tempfile
import time
from typing import Any, IO

from std_srvs.srv import SetBool
from swivel_car_stack import (
    config_path, executable_path, INSTALL_DIR, lockstep_parameters, NodeProcess,
    process_report, REPO_ROOT, ros_environment, spin_until, start_node)

__all__ = ['config_path', 'executable_path', 'INSTALL_DIR', 'lockstep_parameters',
           'next_domain_id', 'NodeProcess', 'process_report', 'remove_unborn_shm_ports',
           'REPO_ROOT', 'resume_sim', 'ros_environment', 'spin_until', 'start_node', 'UNBORN_AGE',
           'DOMAINS_PER_PROCESS']

# Each test run of real nodes gets its own ROS domain, so parallel runs and earlier tests'
# stragglers are never heard. Every process (a pytest-xdist worker, another pytest, the
# benchmark) claims a block of DOMAINS_PER_PROCESS ids of its own with a lock file on this
# host, held until it exits; the search starts at a block chosen by the pid, and skips a block
# on which a live process still runs (a node a killed test run left: it would talk to this
# run's nodes).
DOMAINS_PER_PROCESS = 10
_BLOCKS = 23  # ROS_DOMAIN_ID 1 .. 230 (Fast DDS allows at most 232)
_LOCK_DIR = Path(tempfile.gettempdir()) / 'swivel_car_ros_domains'
_held: list[IO[str]] = []
_domain_ids: itertools.cycle | None = None
UNBORN_AGE = 60.0  # [s] see remove_unborn_shm_ports


def remove_unborn_shm_ports(shm_dir: Path = Path('/dev/shm')) -> list[str]:
    """
    Delete Fast DDS shared-memory ports that were never initialized and that no process holds.

    A process killed while it created its port leaves the port's file all zeros, without a
    lock file (so `fastdds shm clean` keeps it). A participant that later gets the same port
    (the same domain and participant index) waits for its initialization forever, inside
    rclpy's Node(): seen here, a planner blocked for 15 minutes in
    SharedMemGlobal::open_port_internal, on a port file left six hours earlier. Returns the
    names of the files deleted.

    Only files last changed ``UNBORN_AGE`` or longer ago: a port being created is all zeros
    for a moment, and its creator may have opened it after this scan read its process.
    Deleted then, the creator would listen on a file nobody else can open.
    """
    changed_before = time.time() - UNBORN_AGE  # [s] since the epoch
    held: set[str] = set()
    for process in Path('/proc').iterdir():
        if not process.name.isdigit():
            continue
        try:
            held.update(os.readlink(fd) for fd in (process / 'fd').iterdir())
            held.update(line.split(maxsplit=5)[-1] for line in
                        (process / 'maps').read_text().splitlines() if '/' in line)
        except OSError:
            continue  # ended meanwhile, or not ours to read
    removed = []
    for port in shm_dir.glob('fastrtps_port*'):
        if port.name.endswith(('_el', '_sl')) or str(port) in held:
            continue
        try:
            unborn = port.stat().st_mtime < changed_before and not any(port.read_bytes())
        except OSError:
            continue
        if unborn:
            for name in (port.name, f'sem.{port.name}_mutex'):
                (shm_dir / name).unlink(missing_ok=True)
            removed.append(port.name)
    return removed


def resume_sim(executor: Any, set_paused: Any, timeout: float = 60.0) -> None:
    """
    Resume a sim started paused once the ``set_paused`` client (its ~/set_paused) has found it.

    A stack's sim starts paused so that it does not run tens of seconds of sim time for nothing
    while the test's node discovers it (some 2.3 s). Not waiting for the answer: a server that
    has not yet discovered the caller's response reader drops it; the stack running shows the
    sim resumed.
    """
    spin_until(executor, set_paused.service_is_ready, timeout, set_paused.srv_name)
    set_paused.call_async(SetBool.Request(data=False))


def domains_in_use(proc: Path = Path('/proc')) -> set[int]:
    """Return the ROS_DOMAIN_IDs in the environments of the live processes we may read."""
    domains = set()
    for process in proc.iterdir():
        if not process.name.isdigit():
            continue
        try:
            environment = (process / 'environ').read_bytes()
        except OSError:
            continue  # ended meanwhile, or not ours to read
        for entry in environment.split(b'\0'):
            if entry.startswith(b'ROS_DOMAIN_ID='):
                value = entry.removeprefix(b'ROS_DOMAIN_ID=')
                if value.isdigit():
                    domains.add(int(value))
    return domains


def _block_domains(block: int) -> range:
    """Return the ROS_DOMAIN_IDs of block ``block``."""
    return range(1 + DOMAINS_PER_PROCESS * block, 1 + DOMAINS_PER_PROCESS * (block + 1))


def _claim_block() -> int:
    remove_unborn_shm_ports()
    _LOCK_DIR.mkdir(exist_ok=True)
    in_use = domains_in_use()
    for k in range(_BLOCKS):
        block = (os.getpid() + k) % _BLOCKS
        if in_use.intersection(_block_domains(block)):
            continue
        lock = open(_LOCK_DIR / f'{block}.lock', 'w')
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            lock.close()
            continue
        _held.append(lock)
        return block
    return os.getpid() % _BLOCKS  # more than 23 processes at once: share one block


def next_domain_id() -> int:
    """
    Return a ROS_DOMAIN_ID that no other process using this helper on this host has.

    Nor did the previous DOMAINS_PER_PROCESS - 1 calls in this process return it.
    """
    global _domain_ids
    if _domain_ids is None:
        _domain_ids = itertools.cycle(_block_domains(_claim_block()))
    return next(_domain_ids)
