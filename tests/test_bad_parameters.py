"""
A bad parameter at start ends every node with one [FATAL] line naming it.

A parameter of the wrong type or value: exit code 1 and no traceback (issue 12: before,
rclpy's InvalidParameterTypeException, and any bad planner value); an integer where a number
is due is that number. Each executable is started once with a bad value; the other bad values
are given to the node class in this process, through the same command-line arguments: the
executable's main turns what they raise into that one line.
"""

import os
import subprocess

import pytest
from rclpy.exceptions import ParameterException
from rclpy.parameter import Parameter

from swivel_car_control.controller_node import ControllerNode
from swivel_car_control.odometry_node import OdometryNode
from swivel_car_perception.step_detector_node import StepDetectorNode
from swivel_car_planner.planner_node import PlannerNode
from swivel_car_sim.sim_node import SimNode
from swivel_car_testing import next_domain_id, REPO_ROOT

INSTALL = REPO_ROOT / 'ros2_ws' / 'install'
EXECUTABLE_CASES = [
    ('swivel_car_sim', 'sim_node', 'lockstep', 'maybe'),
    ('swivel_car_control', 'controller_node', 'use_stamped', '7'),
    ('swivel_car_control', 'odometry_node', 'publish_rate', 'fast'),
    ('swivel_car_planner', 'planner_node', 'time_allowance', '[1.0]'),
]
NODE_CASES = [
    (SimNode, 'body_mass', 'heavy'),
    (SimNode, 'time_step', '-1.0'),
    (ControllerNode, 'lockstep_wait', 'long'),
    (ControllerNode, 'lockstep_cmd_vel', 'maybe'),
    (ControllerNode, 'kp', '.nan'),
    (PlannerNode, 'body_mass', '-1.0'),
    (PlannerNode, 'ready_timeout', '-1.0'),
    (PlannerNode, 'ready_timeout', 'soon'),
    (PlannerNode, 'approach_speed', '.nan'),
    (PlannerNode, 'max_reposition', '-1.0'),
    (PlannerNode, 'reposition_clearance', '.nan'),
    (PlannerNode, 'detection_max_age', '-1.0'),
    (SimNode, 'clock_source', 'sundial'),
    (StepDetectorNode, 'min_height', '-0.01'),
    (StepDetectorNode, 'max_distance', 'far'),
]


@pytest.mark.parametrize('package, executable, name, value', EXECUTABLE_CASES)
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


@pytest.mark.parametrize('node_class, name, value', NODE_CASES,
                         ids=lambda v: getattr(v, '__name__', str(v)))
def test_a_bad_value_is_refused_as_the_executable_reports_it(
        ros_domain, node_class, name, value):
    with pytest.raises((ValueError, ParameterException)) as refused:
        node = node_class(context=ros_domain[1],
                          cli_args=['--ros-args', '-p', f'{name}:={value}'])
        node.destroy_node()
    assert name in str(refused.value)


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
