"""
robot_description_node: the robot on the graph.

robot_state_publisher's part for machines that lack it. The URDF generated from the robot
description (the same parameters as every node) on ``robot_description`` (std_msgs/String,
transient local, so late subscribers get it); and, where ``tf2_msgs`` is installed, the fixed
joints' frames on ``/tf_static`` and the moving joints' frames from ``joint_states`` on ``/tf``.

On a full Jazzy install, robot_state_publisher with the installed URDF
(``share/swivel_car_sim/urdf/swivel_car.urdf``) does the same: run one of the two.
"""

from __future__ import annotations

import dataclasses
import sys

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from swivel_car_bringup.robot_frames import fixed_frames, Frame, moving_frames, parse_joints
from swivel_car_model.description import ROBOT_VARIANTS
from swivel_car_ros.ros_params import declare_description, refuse_runtime_changes, \
    run_node
from swivel_car_sim.urdf import build_robot

LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


class RobotDescriptionNode(Node):
    """Publishes the URDF and, with tf2_msgs, the robot's frames."""

    def __init__(self, **kwargs) -> None:
        super().__init__('robot_description', **kwargs)
        robot = declare_description(self)
        variant = self.declare_parameter('robot_variant', 'swivel', ParameterDescriptor(
            description=f"{' or '.join(ROBOT_VARIANTS)}, as the sim's")).value
        self.declare_parameter('frame_prefix', '', ParameterDescriptor(
            description="prefix of the link frames on /tf, e.g. 'robot1/'"))
        refuse_runtime_changes(self, {f.name for f in dataclasses.fields(robot)}
                               | {'robot_variant', 'frame_prefix'})
        if variant not in ROBOT_VARIANTS:
            raise ValueError(f'robot_variant must be one of {ROBOT_VARIANTS}, got {variant!r}')
        self.urdf = build_robot(robot, variant).urdf
        self._joints = parse_joints(self.urdf)
        self._prefix = self.get_parameter('frame_prefix').value
        self.create_publisher(String, 'robot_description', LATCHED).publish(
            String(data=self.urdf))
        self._tf = self._tf_publishers()

    def _tf_publishers(self):
        try:
            from geometry_msgs.msg import TransformStamped
            from tf2_msgs.msg import TFMessage
        except ImportError as error:
            self.get_logger().warn(
                f"tf2_msgs is not importable ({error}): NOT publishing the robot's frames on "
                '/tf and /tf_static; robot_description is published, and the Foxglove bridge '
                'computes the frames itself')
            return None
        static = [self._transform(TransformStamped, frame, self.get_clock().now().to_msg())
                  for frame in fixed_frames(self._joints)]
        if static:
            self.create_publisher(TFMessage, '/tf_static', LATCHED).publish(
                TFMessage(transforms=static))
        self.create_subscription(JointState, 'joint_states', self._on_joint_states, 10)
        return TransformStamped, TFMessage, self.create_publisher(TFMessage, '/tf', 100)

    def _transform(self, transform_class, frame: Frame, stamp):
        transform = transform_class()
        transform.header.stamp = stamp
        transform.header.frame_id = self._prefix + frame.parent
        transform.child_frame_id = self._prefix + frame.child
        t, r = transform.transform.translation, transform.transform.rotation
        t.x, t.y, t.z = frame.translation
        r.x, r.y, r.z, r.w = frame.rotation
        return transform

    def _on_joint_states(self, msg: JointState) -> None:
        transform_class, message_class, publisher = self._tf
        frames = moving_frames(self._joints, dict(zip(msg.name, msg.position)))
        if frames:
            publisher.publish(message_class(transforms=[
                self._transform(transform_class, frame, msg.header.stamp) for frame in frames]))


def main(args=None) -> None:
    sys.exit(run_node(RobotDescriptionNode, 'robot_description', args))


if __name__ == '__main__':
    main()
