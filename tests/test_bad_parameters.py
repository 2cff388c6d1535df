"""
A bad parameter at start ends every node with one [FATAL] line naming it.

A parameter of the wrong type or value: exit code 1 and no traceback (issue 12: before,
rclpy's InvalidParameterTypeException, and any bad planner value); an integer where a number
is due is that number.
"""

import os
import subprocess

import pytest
from rclpy.parameter import Parameter

from swivel_car_control.controller_node import ControllerNode
from swivel_car_control.odometry_node import OdometryNode
from swivel_car_planner.planner_node import PlannerNode
from swivel_car_sim.sim_node import SimNode
from swivel_car_testing import next_domain_id, REPO_ROOT

INSTALL = REPO_ROOT / 'ros2_ws' / 'install'
CASES = [
    ('swivel_car_sim', 'sim_node', 'lockstep', 'maybe'),
    ('swivel_car_control', 'controller_node', 'use_stamped', '7'),
    ('swivel_car_control', 'odometry_node', 'publish_rate', 'fast'),
    ('swivel_car_planner', 'planner_node', 'time_allowance', '[1.0]'),
    ('swivel_car_sim', 'sim_node', 'body_mass', 'heavy'),
    ('swivel_car_sim', 'sim_node', 'time_step', '-1.0'),
    ('swivel_car_control', 'controller_node', 'lockstep_wait', 'long'),
    ('swivel_car_control', 'controller_node', 'lockstep_cmd_vel', 'maybe'),
    ('swivel_car_control', 'controller_node', 'kp', '.nan'),
    ('swivel_car_planner', 'planner_node', 'body_mass', '-1.0'),
    ('swivel_car_planner', 'planner_node', 'ready_timeout', '-1.0'),
    ('swivel_car_planner', 'planner_node', 'ready_timeout', 'soon'),
    ('swivel_car_planner', 'planner_node', 'approach_speed', '.nan'),
]


@pytest.mark.parametrize('package, executable, name, value', CASES)
def test_a_wrong_type_at_start_is_one_fatal_line_and_exit_1(package, executable, name, value):
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               ROS_DOMAIN_ID=str(next_domain_id()))
    done = subprocess.run(
        [str(REPO_ROOT / 'scripts' / 'in_ws'),
         str(INSTALL / package / 'lib' / package / executable),
         '--ros-args', '-p', f'{name}:={value}'],
        env=env, capture_output=True, text=True, timeout=60)
    output = done.stdout + done.stderr
    assert done.returncode == 1, output
    assert 'Traceback' not in output
    fatal = [line for line in output.splitlines() if '[FATAL]' in line]
    assert len(fatal) == 1 and name in fatal[0], output


@pytest.mark.parametrize('node_class, name', [
    (SimNode, 'body_mass'), (SimNode, 'real_time_factor'), (ControllerNode, 'body_mass'),
    (ControllerNode, 'lockstep_wait'), (OdometryNode, 'body_mass'),
    (OdometryNode, 'publish_rate'), (PlannerNode, 'body_mass'),
    (PlannerNode, 'ready_timeout'), (PlannerNode, 'approach_speed')])
def test_an_integer_where_a_number_is_due_is_that_number(ros_domain, node_class, name):
    """`body_mass:=3` is how users write it; YAML reads an integer."""
    node = node_class(context=ros_domain[1], parameter_overrides=[
        Parameter(name, value=1), Parameter('start_paused', value=True)])
    try:
        assert node.get_parameter(name).value == 1
    finally:
        node.destroy_node()
