"""
The test support's removal of Fast DDS shared-memory ports a killed process left unborn.

A participant given such a port waits for it forever inside rclpy's Node(); next_domain_id
removes them before a process's first domain (swivel_car_testing.remove_unborn_shm_ports).
"""

import os
from pathlib import Path
import time

import pytest
from swivel_car_testing import (
    DOMAINS_PER_PROCESS, next_domain_id, NodeProcess, remove_unborn_shm_ports, UNBORN_AGE)


def left_long_ago(*paths: Path) -> None:
    """Date ``paths`` back as a killed run's leftovers are."""
    then = time.time() - 2.0 * UNBORN_AGE  # [s] since the epoch
    for path in paths:
        os.utime(path, (then, then))


def test_only_unborn_ports_that_no_process_holds_are_removed(tmp_path):
    unborn = tmp_path / 'fastrtps_port7411'
    unborn.write_bytes(bytes(52400))
    mutex = tmp_path / 'sem.fastrtps_port7411_mutex'
    mutex.write_bytes(bytes(32))
    kept = [tmp_path / 'fastrtps_port7413', tmp_path / 'fastrtps_port7415',
            tmp_path / 'fastrtps_port7417_el', tmp_path / 'fastrtps_0123456789abcdef']
    kept[0].write_bytes(b'\x01' + bytes(99))  # initialized
    kept[1].write_bytes(bytes(100))  # unborn, but being created: its creator holds it
    kept[2].write_bytes(b'')  # a lock file
    kept[3].write_bytes(bytes(100))  # a data segment, not a port
    left_long_ago(unborn, mutex, *kept)
    kept.append(tmp_path / 'fastrtps_port7419')
    kept[4].write_bytes(bytes(100))  # unborn, but new: its creator may not be seen yet
    with kept[1].open('rb'):
        assert remove_unborn_shm_ports(tmp_path) == [unborn.name]
    assert not unborn.exists() and not mutex.exists()
    assert all(path.exists() for path in kept)


def test_a_node_whose_port_was_left_unborn_starts_once_it_is_removed():
    # Without the removal the node waits forever inside rclpy's Node() (checked by hand: no
    # 'controller up' in 10 s; with it, under a second).
    # Participant 0's discovery and user ports (Fast DDS port rules), made unborn only in a
    # domain where neither exists: written over, a live participant's port is corrupted for
    # good (not all zeros, so never removed), and every later participant 0 of that domain
    # hangs in Node().
    for _ in range(DOMAINS_PER_PROCESS):
        domain_id = next_domain_id()
        ports = [Path(f'/dev/shm/fastrtps_port{7400 + 250 * domain_id + offset}')
                 for offset in (10, 11)]
        if not any(port.exists() for port in ports):
            break
    else:
        pytest.fail("participant 0's ports exist in all of this process's domains")
    for port in ports:
        with port.open('xb') as file:  # never over a port that appeared meanwhile
            file.write(bytes(52400))
    left_long_ago(*ports)
    remove_unborn_shm_ports()
    # Gone, whoever removed them: another test worker claiming its first domain removes
    # unborn ports too.
    assert not any(port.exists() for port in ports)
    node = NodeProcess('swivel_car_control', 'controller_node', domain_id, {})
    try:
        node.wait_for_output('controller up', 60.0)
    finally:
        node.stop()
