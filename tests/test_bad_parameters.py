"""A parameter of the wrong type at start ends every node with one [FATAL] line naming it,
exit code 1 and no traceback (issue 12: before, rclpy's InvalidParameterTypeException)."""

import os
import subprocess

import pytest

from swivel_car_testing import REPO_ROOT, next_domain_id

INSTALL = REPO_ROOT / 'ros2_ws' / 'install'
CASES = [
    ('swivel_car_sim', 'sim_node', 'lockstep', 'maybe'),
    ('swivel_car_control', 'controller_node', 'use_stamped', '7'),
    ('swivel_car_control', 'odometry_node', 'publish_rate', 'fast'),
    ('swivel_car_planner', 'planner_node', 'time_allowance', '[1.0]'),
]


@pytest.mark.parametrize('package, executable, name, value', CASES)
def test_a_wrong_type_at_start_is_one_fatal_line_and_exit_1(package, executable, name, value):
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               ROS_DOMAIN_ID=str(next_domain_id()))
    done = subprocess.run(
        [str(REPO_ROOT / 'scripts' / 'in_ws'), str(INSTALL / package / 'lib' / package / executable),
         '--ros-args', '-p', f'{name}:={value}'],
        env=env, capture_output=True, text=True, timeout=60)
    output = done.stdout + done.stderr
    assert done.returncode == 1, output
    assert 'Traceback' not in output
    fatal = [line for line in output.splitlines() if '[FATAL]' in line]
    assert len(fatal) == 1 and name in fatal[0], output
