"""
Root conftest: import the stack's packages before pytest collects their tests.

With --import-mode=importlib pytest names a test module after its path
(swivel_car_sim/test/test_physics.py -> swivel_car_sim.test.test_physics) and puts empty
stand-ins into sys.modules for parents it has not seen, which would hide the real
swivel_car_sim package from the tests. Importing the real packages first prevents that, and
lets same-named test files (test_system.py) live in several packages.

Hypothesis draws the same examples on every run, so a test run's result depends on the code
alone (HYPOTHESIS_PROFILE=explore draws new ones, for looking for bugs by hand). Neither has a
deadline: an example's wall time depends on the machine's load (one took 414 ms against the
default 200 ms with three test processes on two cores).

The files pytest.ini names in ``run_first`` are collected first, in that order.

``-n auto`` (``make test``) starts one pytest-xdist worker more than the cores the process may
run on: a worker waits part of the time (the stack test's wall-paced drives, a node's start
and discovery), and on the 2-core machine 3 workers took 118-129 s where 2 took 141 s. A
fourth kept both cores busy (117-123 s where 3 took 131-137 s), but starved the one test on
the system clock: tests/test_hardware_time.py failed in 1 of 14 whole runs, the planner
reaching the lift point 0.60 rad off its heading (with 3 workers: in none of 13 runs).
PYTEST_XDIST_AUTO_NUM_WORKERS overrides the count, as pytest-xdist documents.

Every participant of the test processes, and of the nodes they start (which inherit the
environment), reads tests/support/fastdds_test_profile.xml: under the suite's load the
default socket buffers dropped datagrams (Udp RcvbufErrors), and a reliable topic then
stalled until Fast DDS's next heartbeat, 3 s later by default.
"""

import importlib
import os
from pathlib import Path

from hypothesis import settings
import pytest

os.environ['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(
    Path(__file__).resolve().parent / 'tests' / 'support' / 'fastdds_test_profile.xml')

for package in ('swivel_car_control', 'swivel_car_model', 'swivel_car_perception',
                'swivel_car_planner', 'swivel_car_ros', 'swivel_car_sim', 'swivel_car_studies',
                'swivel_car_telemetry'):
    importlib.import_module(package)

settings.register_profile('deterministic', derandomize=True, deadline=None)
settings.register_profile('explore', derandomize=False, deadline=None)
settings.load_profile(os.environ.get('HYPOTHESIS_PROFILE', 'deterministic'))


def pytest_xdist_auto_num_workers(config):
    if 'PYTEST_XDIST_AUTO_NUM_WORKERS' in os.environ:
        return None  # pytest-xdist's own hook reads it
    return len(os.sched_getaffinity(0)) + 1


def pytest_addoption(parser):
    parser.addini('run_first', 'test files collected before the others, in this order',
                  type='linelist')


def pytest_collection_modifyitems(config, items):
    first = config.getini('run_first')
    missing = [path for path in first if not (config.rootpath / path).is_file()]
    if missing:
        raise pytest.UsageError(f'pytest.ini run_first names no such file: {missing}')
    rank = {path: index for index, path in enumerate(first)}
    items.sort(key=lambda item: rank.get(item.location[0], len(first)))
