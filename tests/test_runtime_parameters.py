"""
Runtime `ros2 param set` on every node, the ROS 2 way.

A parameter either applies live or is read-only, and a bad value is refused with the reason
`ros2 param set` prints. Before (issue 12), `param set /sim time_step -1`,
`real_time_factor 0.5` or a NaN was "Set parameter successful" and nothing changed.
"""

import math

from nav_msgs.msg import Odometry
import pytest
from rclpy.parameter import Parameter
from rclpy.serialization import deserialize_message

from swivel_car_control.controller_node import ControllerNode
from swivel_car_control.odometry_node import OdometryNode
from swivel_car_planner.planner_node import PlannerNode
from swivel_car_sim.sim_node import SimNode


@pytest.fixture
def make_node(ros_domain):
    _, context = ros_domain
    nodes = []

    def make(node_class, *overrides):
        node = node_class(context=context, parameter_overrides=list(overrides))
        nodes.append(node)
        return node

    yield make
    for node in nodes:
        node.destroy_node()


def set_one(node, name, value):
    return node.set_parameters([Parameter(name, value=value)])[0]


@pytest.mark.parametrize('node_class, name, value', [
    (SimNode, 'time_step', -1.0), (SimNode, 'real_time_factor', 0.5),
    (SimNode, 'body_mass', math.nan), (SimNode, 'lockstep', True),
    (ControllerNode, 'max_linear_velocity', 1.0), (ControllerNode, 'body_mass', 3.0),
    (ControllerNode, 'use_stamped', False), (ControllerNode, 'lockstep_wait', 0.1),
    (ControllerNode, 'lockstep_cmd_vel', True),
    (OdometryNode, 'publish_rate', 50.0), (OdometryNode, 'yaw_rate_source', 'rear_wheels'),
    (PlannerNode, 'body_mass', -1.0), (PlannerNode, 'ready_timeout', 3.0),
    (PlannerNode, 'capability_file', 'none')])
def test_a_parameter_read_at_start_is_read_only(make_node, node_class, name, value):
    node = make_node(node_class, Parameter('start_paused', value=True))
    before = node.get_parameter(name).value
    result = set_one(node, name, value)
    assert not result.successful
    assert result.reason == f'Trying to set a read-only parameter: {name}.'
    assert node.describe_parameter(name).read_only
    assert node.get_parameter(name).value == before


def test_the_controllers_deadmans_and_slowdown_apply_live(make_node):
    node = make_node(ControllerNode)
    assert set_one(node, 'cmd_vel_timeout', 2).successful  # an integer for a double
    assert set_one(node, 'swivel_command_timeout', 0.25).successful
    assert set_one(node, 'slowdown_stop', 0.8).successful
    config = node._core.config
    assert (config.cmd_vel_timeout, config.swivel_command_timeout,
            config.slowdown_stop) == (2.0, 0.25, 0.8)


@pytest.mark.parametrize('name, value, reason', [
    ('cmd_vel_timeout', -1.0, 'cmd_vel_timeout must be a finite number >= 0'),
    ('cmd_vel_timeout', math.nan, 'cmd_vel_timeout must be a finite number >= 0'),
    ('swivel_command_timeout', 'long', 'swivel_command_timeout must be a finite number'),
    ('slowdown_start', 1.0, 'need 0 <= slowdown_start <= slowdown_stop')])
def test_a_bad_live_controller_value_is_refused_with_the_reason(make_node, name, value,
                                                                reason):
    node = make_node(ControllerNode)
    before = node._core.config
    result = set_one(node, name, value)
    assert not result.successful and reason in result.reason
    assert node._core.config is before


def test_the_odometry_covariances_apply_live_and_bad_ones_are_refused(make_node):
    node = make_node(OdometryNode)
    assert set_one(node, 'pose_covariance_diagonal', [0.5] * 6).successful
    published = deserialize_message(node._odom.serialized(), Odometry)
    assert published.pose.covariance[0] == 0.5
    result = set_one(node, 'twist_covariance_diagonal', [0.1, math.nan, 0.0, 0.0, 0.0, 0.0])
    assert not result.successful and 'twist_covariance_diagonal must be 6 finite numbers' \
        in result.reason
    result = set_one(node, 'twist_covariance_diagonal', 0.1)
    assert not result.successful and 'lists of 6 numbers' in result.reason
    published = deserialize_message(node._odom.serialized(), Odometry)
    assert published.twist.covariance[0] == 0.001


def test_the_planners_climb_settings_apply_from_the_next_climb(make_node):
    node = make_node(PlannerNode)
    assert set_one(node, 'approach_speed', 1).successful  # an integer for a double
    assert node.config.approach_speed == 1
    for value, reason in ((math.nan, 'approach_speed must be a finite number'),
                          (-0.1, 'approach_speed must be >= 0'),
                          ('fast', 'approach_speed must be a finite number')):
        result = set_one(node, 'approach_speed', value)
        assert not result.successful and reason in result.reason
    assert node.config.approach_speed == 1
