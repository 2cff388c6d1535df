"""
robot_description_node: the robot on the graph, as robot_state_publisher puts it there.

The URDF generated from the robot description (the same parameters as every node) on
``robot_description`` (std_msgs/String, transient local, so late subscribers get it); the
fixed joints' frames on ``/tf_static`` (transient local, once); the moving joints' frames from
``joint_states`` on ``/tf``, stamped with their joint_states, at most ``publish_frequency``
by joint_states time. Link frames carry ``frame_prefix``. With the odometry's odom ->
base_link, every link of the URDF is placed.

On a full Jazzy install, robot_state_publisher with the installed URDF
(``share/swivel_car_sim/urdf/swivel_car.urdf``) does the same: run one of the two.
"""

from __future__ import annotations

import dataclasses
import sys

from geometry_msgs.msg import TransformStamped
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import JointState
from std_msgs.msg import String

from swivel_car_model.description import ROBOT_VARIANTS
from swivel_car_ros.ros_params import declare_description, refuse_runtime_changes, \
    run_node, stamp_to_seconds, STATE_QUEUE_DEPTH
from swivel_car_ros.serialized import read_joint_state, read_logged
from swivel_car_sim.urdf import build_robot
from swivel_car_telemetry.robot_frames import fixed_frames, Frame, moving_frames, parse_joints, \
    RateLimit
from tf2_msgs.msg import TFMessage

# robot_description and /tf_static: tf2_ros' StaticBroadcasterQoS. /tf: its
# DynamicBroadcasterQoS.
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
TF_QOS = QoSProfile(depth=100)


class RobotDescriptionNode(Node):
    """Publishes the URDF and the robot's link frames."""

    def __init__(self, **kwargs) -> None:
        super().__init__('robot_description', **kwargs)
        robot = declare_description(self)
        variant = self.declare_parameter('robot_variant', 'swivel', ParameterDescriptor(
            description=f"{' or '.join(ROBOT_VARIANTS)}, as the sim's")).value
        self._prefix = self.declare_parameter('frame_prefix', '', ParameterDescriptor(
            description="prefix of the link frames on /tf and /tf_static, e.g. 'robot1/'")).value
        frequency = self.declare_parameter('publish_frequency', 20.0, ParameterDescriptor(
            description='most /tf messages per second of joint_states time, as '
                        "robot_state_publisher's [Hz]")).value
        refuse_runtime_changes(self, {f.name for f in dataclasses.fields(robot)}
                               | {'robot_variant', 'frame_prefix', 'publish_frequency'})
        if variant not in ROBOT_VARIANTS:
            raise ValueError(f'robot_variant must be one of {ROBOT_VARIANTS}, got {variant!r}')
        if not (isinstance(frequency, (int, float)) and frequency > 0.0):
            raise ValueError(f'publish_frequency must be > 0 Hz, got {frequency!r}')
        self._rate = RateLimit(1.0 / frequency)
        self.urdf = build_robot(robot, variant).urdf
        self._joints = parse_joints(self.urdf)
        self.create_publisher(String, 'robot_description', LATCHED).publish(
            String(data=self.urdf))
        # Published even when empty, as robot_state_publisher does: a reader sees the topic.
        stamp = self.get_clock().now().to_msg()
        self.create_publisher(TFMessage, '/tf_static', LATCHED).publish(TFMessage(transforms=[
            self._transform(frame, stamp) for frame in fixed_frames(self._joints)]))
        self._tf = self.create_publisher(TFMessage, '/tf', TF_QOS)
        # Raw and read at its offsets: most joint_states are dropped by the rate limit.
        self.create_subscription(JointState, 'joint_states', self._on_joint_states,
                                 STATE_QUEUE_DEPTH, raw=True)

    def _transform(self, frame: Frame, stamp) -> TransformStamped:
        transform = TransformStamped(child_frame_id=self._prefix + frame.child)
        transform.header.stamp = stamp
        transform.header.frame_id = self._prefix + frame.parent
        t, r = transform.transform.translation, transform.transform.rotation
        t.x, t.y, t.z = frame.translation
        r.x, r.y, r.z, r.w = frame.rotation
        return transform

    def _on_joint_states(self, data: bytes) -> None:
        msg = read_logged(self.get_logger(), read_joint_state, data, 'joint_states')
        if msg is None or not self._rate.due(stamp_to_seconds(msg.stamp)):
            return
        frames = moving_frames(self._joints, dict(zip(msg.name, msg.position)))
        if frames:
            self._tf.publish(TFMessage(transforms=[
                self._transform(frame, msg.stamp) for frame in frames]))


def main(args=None) -> None:
    sys.exit(run_node(RobotDescriptionNode, 'robot_description', args))


if __name__ == '__main__':
    main()
