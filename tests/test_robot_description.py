"""
Every node runs the one robot description (swivel_car_model.description).

With its installed configuration each node declares the description's parameters with the
description's values, and its cores are built from them. A copy that drifts fails here.
"""

from __future__ import annotations

from dataclasses import fields

import pytest
import rclpy
from swivel_car_control.controller_node import ControllerNode
from swivel_car_control.odometry_node import OdometryNode
from swivel_car_model import description
from swivel_car_model.description import CarDescription
from swivel_car_perception.step_detector_node import StepDetectorNode
from swivel_car_planner.planner_node import PlannerNode
from swivel_car_sim.sim_node import SimNode
from swivel_car_stack import config_path
from swivel_car_testing import next_domain_id

NODES = [(SimNode, 'swivel_car_sim', 'sim_node.yaml'),
         (ControllerNode, 'swivel_car_control', 'controller_node.yaml'),
         (OdometryNode, 'swivel_car_control', 'odometry_node.yaml'),
         (PlannerNode, 'swivel_car_planner', 'planner_node.yaml'),
         (StepDetectorNode, 'swivel_car_perception', 'step_detector_node.yaml')]


def _node(node_class, package, config, overrides=()):
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=next_domain_id(), args=[
        '--ros-args', '--params-file', str(config_path(package, config)),
        *[item for name, value in overrides for item in ('-p', f'{name}:={value}')]])
    return node_class(context=context), context


def _close(node, context):
    node.destroy_node()
    rclpy.try_shutdown(context=context)


@pytest.mark.parametrize('node_class, package, config', NODES, ids=lambda v: getattr(
    v, '__name__', ''))
def test_each_node_declares_the_description_with_its_values(node_class, package, config):
    node, context = _node(node_class, package, config)
    try:
        expected = CarDescription()
        for name in description.PARAMETERS:
            assert node.get_parameter(name).value == getattr(expected, name), name
    finally:
        _close(node, context)


def test_each_node_builds_its_cores_from_one_override():
    # A user changes the robot once, for every node (here: one -p per node, as a `/**:`
    # params file does): every core sees it.
    changed = CarDescription(body_mass=14.0, body_offset=0.05, rear_axle_mass=1.2,
                             rear_differential='locked', swivel_torque_limit=25.0, kp=120.0)
    overrides = [(item.name, getattr(changed, item.name)) for item in fields(changed)
                 if getattr(changed, item.name) != getattr(CarDescription(), item.name)]
    for node_class, package, config in NODES:
        node, context = _node(node_class, package, config, overrides)
        try:
            if node_class is SimNode:
                assert node.sim.description == changed
            elif node_class is ControllerNode:
                assert node._core.p == changed.model_params()
                assert node._core.config.max_torque == 25.0
            elif node_class is OdometryNode:
                assert node._car == changed.model_params()
            elif node_class is StepDetectorNode:
                # The camera sits on the central body, which body_offset moves.
                assert tuple(node._mount.position) == tuple(changed.camera_mount()[0])
                assert node._mount.front_axle == changed.wheelbase
            else:
                assert node.robot == changed.model_params()
                assert node.description == changed
        finally:
            _close(node, context)
