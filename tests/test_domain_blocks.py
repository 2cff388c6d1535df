"""
The test support's ROS domain blocks: a block a live process still runs on is not claimed.

A node left running by a killed test run (kill -9 of pytest does not reach the nodes it
started, which run in sessions of their own) keeps talking on its domain; a new run's node on
the same domain would hear two sims.
"""

import os
from pathlib import Path
import subprocess
import sys

import swivel_car_testing


def test_the_domains_of_live_processes_are_found_and_an_ended_ones_are_not():
    # 9999: no ROS process uses it (Fast DDS takes 0..232; other test workers' nodes use 1..230).
    # Until the child has run its own program, /proc shows the environment it was forked with,
    # this process's: it says when it runs.
    leftover = subprocess.Popen(
        [sys.executable, '-c', 'import time; print("up", flush=True); time.sleep(60)'],
        env={**os.environ, 'ROS_DOMAIN_ID': '9999'}, stdout=subprocess.PIPE, text=True)
    try:
        assert leftover.stdout.readline() == 'up\n'
        assert 9999 in swivel_car_testing.domains_in_use()
    finally:
        leftover.kill()
        leftover.wait()
        leftover.stdout.close()
    assert 9999 not in swivel_car_testing.domains_in_use()


def test_a_block_with_a_live_process_on_one_of_its_domains_is_skipped(tmp_path, monkeypatch):
    block = os.getpid() % swivel_car_testing._BLOCKS  # the block this process would try first
    monkeypatch.setattr(swivel_car_testing, '_LOCK_DIR', Path(tmp_path))
    monkeypatch.setattr(swivel_car_testing, 'remove_unborn_shm_ports', lambda: [])
    in_block = swivel_car_testing._block_domains(block)[6]  # one of its domains
    monkeypatch.setattr(swivel_car_testing, 'domains_in_use', lambda: {in_block})
    claimed = swivel_car_testing._claim_block()
    try:
        assert claimed == (block + 1) % swivel_car_testing._BLOCKS
    finally:
        swivel_car_testing._held.pop().close()
