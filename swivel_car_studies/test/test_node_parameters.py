"""
The nodes' parameters against what is stated about them elsewhere.

Each node is constructed in-process with its defaults, as ``scripts/node_docs.py`` does: its
declarations are the schema (name, default, type, description; the node refuses a bad value
at start). Checked against it: the chain's ROS-only names (``swivel_car_ros.chain``), the
in-process stack's overrides, and the shipped ``config/<executable>.yaml`` files.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import rclpy
from rclpy.parameter import Parameter
from swivel_car_control.controller_node import ControllerNode
from swivel_car_control.odometry_node import OdometryNode
from swivel_car_model.description import PARAMETERS as DESCRIPTION
from swivel_car_perception.step_detector_node import StepDetectorNode
from swivel_car_planner.planner_node import PlannerNode
from swivel_car_ros.chain import CHAIN, ROS_ONLY
from swivel_car_sim.depth_camera import PARAMETERS as CAMERA_PARAMETERS
from swivel_car_sim.sim_node import SimNode
from swivel_car_studies.inprocess import StackConfig
from swivel_car_testing import next_domain_id
import yaml

ROOT = Path(__file__).resolve().parents[2]
# node name -> (its class, the parameter file it ships)
NODES = {
    'sim': (SimNode, ROOT / 'swivel_car_sim/config/sim_node.yaml'),
    'controller': (ControllerNode, ROOT / 'swivel_car_control/config/controller_node.yaml'),
    'odometry': (OdometryNode, ROOT / 'swivel_car_control/config/odometry_node.yaml'),
    'planner': (PlannerNode, ROOT / 'swivel_car_planner/config/planner_node.yaml'),
    'step_detector': (StepDetectorNode,
                      ROOT / 'swivel_car_perception/config/step_detector_node.yaml'),
}
# The files' deliberate departures from a node's defaults: the nodes run on /clock.
SHIPPED_CHOICES = {'use_sim_time': True}


def declared(name: str, overrides: dict | None = None) -> dict:
    """Return the parameters node ``name`` declares, with their values, given ``overrides``."""
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=next_domain_id())
    try:
        node = NODES[name][0](context=context, parameter_overrides=[
            Parameter(key, value=value) for key, value in (overrides or {}).items()])
        try:
            assert node.get_name() == name
            return {parameter: node.get_parameter(parameter).value
                    for parameter in node._parameters
                    if parameter != 'start_type_description_service'}
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def _kind(value) -> type:
    # A number is a number: a float field's parameter is dynamically typed (so that `kp:=19`
    # passes); an integer field's is an integer, and the node refuses a file's 3.0 for it
    # (the last check of test_a_shipped_parameter_file_repeats_the_declared_defaults).
    return float if isinstance(value, int) and not isinstance(value, bool) else type(value)


def shipped(name: str) -> dict:
    data = yaml.safe_load(NODES[name][1].read_text())
    return data['/**'][name]['ros__parameters']


@pytest.mark.parametrize('name', CHAIN)
def test_a_node_declares_its_ros_only_parameters_and_the_stack_takes_the_others(name):
    # Every parameter of the node is either ROS-only or one the in-process stack reads: a
    # parameter added to a node and missed by both fails here, not only in the identity run.
    values = declared(name)
    assert ROS_ONLY[name] <= set(values)
    # Each parameter, set to the node's default, is taken by the stack (an unknown one raises).
    # The depth camera's are not: the stack's camera (enable_detection) has its defaults.
    # robot_variant is the stack's first argument.
    others = set(values) - ROS_ONLY[name] - set(CAMERA_PARAMETERS) - {'robot_variant'}
    StackConfig.installed(**{name: {k: values[k] for k in others}})


@pytest.mark.parametrize('name', NODES)
def test_a_shipped_parameter_file_repeats_the_declared_defaults(name):
    # Every key is one the node declares, of the type of its default and equal to it (the
    # file documents the defaults; a change made in one place only fails here), and the node
    # starts with the file's values. The file names every parameter of the node but rclpy's
    # own, the robot description's (stated once, in swivel_car_model) and the sim's depth
    # camera's (off by default; swivel_car_sim.depth_camera states them).
    defaults, values = declared(name), shipped(name)
    assert set(values) <= set(defaults), set(values) - set(defaults)
    unnamed = set(defaults) - set(values) - {'use_sim_time'} - set(DESCRIPTION)
    assert unnamed <= set(CAMERA_PARAMETERS) if name == 'sim' else not unnamed, unnamed
    for key, value in values.items():
        expected = SHIPPED_CHOICES.get(key, defaults[key])
        if isinstance(expected, tuple):
            expected = list(expected)
        assert _kind(value) == _kind(expected) and value == expected, (key, value, expected)
    assert declared(name, values) == {**defaults, **values}
