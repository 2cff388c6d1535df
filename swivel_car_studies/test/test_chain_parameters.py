"""The chain's ROS-only parameters (swivel_car_ros.chain) against the nodes' own."""

from __future__ import annotations

import pytest
import rclpy
from swivel_car_control.controller_node import ControllerNode
from swivel_car_control.odometry_node import OdometryNode
from swivel_car_planner.planner_node import PlannerNode
from swivel_car_ros.chain import CHAIN, ROS_ONLY
from swivel_car_sim.depth_camera import PARAMETERS as CAMERA_PARAMETERS
from swivel_car_sim.sim_node import SimNode
from swivel_car_studies.inprocess import StackConfig
from swivel_car_testing import next_domain_id

NODES = {'controller': ControllerNode, 'odometry': OdometryNode, 'planner': PlannerNode,
         'sim': SimNode}


@pytest.mark.parametrize('name', CHAIN)
def test_a_node_declares_its_ros_only_parameters_and_the_stack_takes_the_others(name):
    # Every parameter of the node is either ROS-only or one the in-process stack reads: a
    # parameter added to a node and missed by both fails here, not only in the identity run.
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=next_domain_id())
    try:
        node = NODES[name](context=context)
        try:
            values = {parameter: node.get_parameter(parameter).value
                      for parameter in node._parameters
                      if parameter != 'start_type_description_service'}
            assert node.get_name() == name
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
    assert ROS_ONLY[name] <= set(values)
    # Each parameter, set to the node's default, is taken by the stack (an unknown one raises).
    # The depth camera's are not: the stack's camera (enable_detection) has its defaults.
    # robot_variant is the stack's first argument.
    others = set(values) - ROS_ONLY[name] - set(CAMERA_PARAMETERS) - {'robot_variant'}
    StackConfig.installed(**{name: {k: values[k] for k in others}})
