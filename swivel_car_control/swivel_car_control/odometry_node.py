"""
odometry_node: tricycle-with-variable-offset odometry from joint_states, on ``odom``.

REP-105: odom -> base_link, twist in base_link; the same pose as the transform odom -> base_link
on ``/tf``, as tf2_ros' TransformBroadcaster sends it (tf2_msgs/TFMessage, reliable, depth 100).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
import math
import sys
from typing import Any, ClassVar

from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState
from std_srvs.srv import Empty
from swivel_car_control.core.joint_states import (
    JointStateOdometry, MAX_SWIVEL_RATE, yaw_quaternion, YAW_RATE_SOURCES)
from swivel_car_control.core.odometry_input import GatedOdometry, Verdict, WHEEL_RATE_FACTOR
from swivel_car_control.joints import MissingJointError
from swivel_car_model.checks import check_nonempty_string
from swivel_car_model.description import described
from swivel_car_msgs.srv import SetPose2D
from swivel_car_ros.ros_params import (
    declare_dataclass, declare_description, live_parameters, run_node, stamp_to_seconds,
    STATE_QUEUE_DEPTH)
from swivel_car_ros.serialized import (
    read_joint_state, read_logged, SerializedMessage, STAMP_FORMAT)
from tf2_msgs.msg import TFMessage


@dataclass(frozen=True)
class OdometryConfig:
    """Frames, rates and covariances of the odometry node (descriptions: each field's metadata)."""

    publish_rate: float = described(
        100.0, 'rate of odom (and TF) messages, by joint_states time: at most one per '
        'joint_states, each stamped with it [Hz]')
    odom_frame_id: str = described('odom', 'fixed frame of the odometry (header.frame_id)')
    base_frame_id: str = described('base_link', 'robot frame (child_frame_id)')
    tf_frame_prefix: str = described(
        '', 'prefix for both frame ids, e.g. a robot name; empty = none')
    enable_odom_tf: bool = described(True, 'broadcast odom -> base_link on /tf')
    # [m^2, m^2, m^2, rad^2, rad^2, rad^2] for x, y, z, roll, pitch, yaw
    pose_covariance_diagonal: tuple = described(
        (0.001, 0.001, 1e6, 1e6, 1e6, 0.01), 'pose covariance diagonal x y z roll pitch yaw '
        '[m^2, rad^2]')
    # [(m/s)^2 x3, (rad/s)^2 x3]
    twist_covariance_diagonal: tuple = described(
        (0.001, 0.001, 1e6, 1e6, 1e6, 0.01), 'twist covariance diagonal [(m/s)^2, (rad/s)^2]')
    swivel_joint: str = described('swivel_joint', 'swivel joint name in joint_states')
    rear_left_wheel_joint: str = described('rear_left_wheel_joint', 'rear left wheel joint name')
    rear_right_wheel_joint: str = described(
        'rear_right_wheel_joint', 'rear right wheel joint name')
    yaw_rate_source: str = described(
        'swivel', "yaw rate from 'swivel' (offset tricycle steering constraint) or 'rear_wheels' "
        '(rear wheel rate difference / track)')
    # What the node applies while running; the rest is read-only.
    LIVE: ClassVar[tuple[str, ...]] = ('pose_covariance_diagonal', 'twist_covariance_diagonal')

    def __post_init__(self) -> None:
        if self.yaw_rate_source not in YAW_RATE_SOURCES:
            raise ValueError(f'yaw_rate_source must be one of {YAW_RATE_SOURCES}, got '
                             f'{self.yaw_rate_source!r}')
        if not (isinstance(self.publish_rate, (int, float)) and math.isfinite(self.publish_rate)
                and self.publish_rate > 0.0):
            raise ValueError(f'publish_rate must be > 0 Hz, got {self.publish_rate!r}')
        for name in ('odom_frame_id', 'base_frame_id', 'swivel_joint', 'rear_left_wheel_joint',
                     'rear_right_wheel_joint'):
            check_nonempty_string(name, getattr(self, name))
        for name in ('pose_covariance_diagonal', 'twist_covariance_diagonal'):
            values = getattr(self, name)
            if len(values) != 6 or not all(
                    isinstance(v, (int, float)) and math.isfinite(v) and v >= 0.0
                    for v in values):
                raise ValueError(f'{name} must be 6 finite numbers >= 0, got {values!r}')

    def frame(self, frame_id: str) -> str:
        """``frame_id`` with the tf prefix ('robot1' + 'odom' -> 'robot1/odom')."""
        prefix = self.tf_frame_prefix.strip('/')
        return f'{prefix}/{frame_id}' if prefix else frame_id


def _diagonal(values: tuple) -> list[float]:
    matrix = [0.0] * 36
    for i, value in enumerate(values):
        matrix[7 * i] = float(value)
    return matrix


class OdometryNode(Node):
    """Offset-tricycle odometry; see the package README for its interface."""

    def __init__(self, **kwargs) -> None:
        super().__init__('odometry', **kwargs)
        robot = declare_description(self)
        self._car = robot.model_params()
        self._config = config = declare_dataclass(self, OdometryConfig)
        joint_odometry = JointStateOdometry(
            self._car, config.swivel_joint, config.rear_left_wheel_joint,
            config.rear_right_wheel_joint, config.yaw_rate_source, config.publish_rate)
        self._odometry = joint_odometry.odometry
        max_wheel_rate = WHEEL_RATE_FACTOR * robot.drive_speed_limit  # [rad/s]
        self._gated = GatedOdometry(joint_odometry, {
            config.swivel_joint: MAX_SWIVEL_RATE, config.rear_left_wheel_joint: max_wheel_rate,
            config.rear_right_wheel_joint: max_wheel_rate})
        # Built once, refilled every period: a message constructor imports and builds each
        # nested message in Python, every time; the odometry is rewritten in its CDR bytes.
        odom = Odometry(child_frame_id=config.frame(config.base_frame_id))
        odom.header.frame_id = config.frame(config.odom_frame_id)
        self._odom = SerializedMessage(odom, (
            (STAMP_FORMAT, ('header.stamp.sec', 'header.stamp.nanosec')),
            ('<7d', tuple(f'pose.pose.position.{c}' for c in 'xyz')
             + tuple(f'pose.pose.orientation.{c}' for c in 'xyzw')),
            ('<36d', ('pose.covariance',)),
            ('<6d', tuple(f'twist.twist.linear.{c}' for c in 'xyz')
             + tuple(f'twist.twist.angular.{c}' for c in 'xyz')),
            ('<36d', ('twist.covariance',))))
        transform = TransformStamped(child_frame_id=odom.child_frame_id)
        transform.header.frame_id = odom.header.frame_id
        self._transform = SerializedMessage(TFMessage(transforms=[transform]), (
            (STAMP_FORMAT, ('transforms.0.header.stamp.sec', 'transforms.0.header.stamp.nanosec')),
            ('<7d', tuple(f'transforms.0.transform.translation.{c}' for c in 'xyz')
             + tuple(f'transforms.0.transform.rotation.{c}' for c in 'xyzw'))))

        self._apply_config(config)
        live_parameters(self, OdometryConfig.LIVE, self._live_config, self._apply_config)
        self._odom_pub = self.create_publisher(Odometry, 'odom', STATE_QUEUE_DEPTH)
        # tf2_ros' DynamicBroadcasterQoS; the message is tf2_msgs' (the workspace builds it
        # where the underlay has none), so no tf2_ros is needed.
        self._tf_pub = self.create_publisher(TFMessage, '/tf', QoSProfile(depth=100)) \
            if config.enable_odom_tf else None
        # Outside the lockstep chain the odometry may trail a busy sim: a second of states
        # queued, so it integrates every one instead of dropping them and Euler-stepping the
        # gap with the last rates.
        self.create_subscription(JointState, 'joint_states', self._on_joint_states,
                                 STATE_QUEUE_DEPTH, raw=True)
        self.create_service(Empty, '~/reset', self._on_reset)
        self.create_service(SetPose2D, '~/set_pose', self._on_set_pose)
        self.get_logger().info(
            f'odometry up: {odom.header.frame_id} -> {odom.child_frame_id}, yaw rate from '
            f'{config.yaw_rate_source}, at most {config.publish_rate:g} Hz')

    def _live_config(self, changes: dict[str, Any]) -> OdometryConfig:
        try:
            values = {name: tuple(value) for name, value in changes.items()}
        except TypeError:
            raise ValueError(f'{", ".join(changes)} must be lists of 6 numbers') from None
        return dataclasses.replace(self._config, **values)

    def _apply_config(self, config: OdometryConfig) -> None:
        self._config = config
        self._odom.pack(2, *_diagonal(config.pose_covariance_diagonal))
        self._odom.pack(4, *_diagonal(config.twist_covariance_diagonal))

    def _on_joint_states(self, data: bytes) -> None:
        msg = read_logged(self.get_logger(), read_joint_state, data, 'joint_states')
        if msg is None:
            return
        t = stamp_to_seconds(msg.stamp)
        try:
            admission, due = self._gated.update(t, msg.name, msg.position, msg.velocity)
        except MissingJointError as error:
            self.get_logger().warn(f'{error}: odometry not updated', throttle_duration_sec=5.0)
            return
        except ValueError as error:
            self.get_logger().warn(f'odometry not updated: {error}', throttle_duration_sec=5.0)
            return
        if admission.verdict is Verdict.REFUSE:
            self.get_logger().warn(f'joint_states refused, odometry not updated: '
                                   f'{admission.reason}', throttle_duration_sec=5.0)
        elif admission.verdict is Verdict.RESTART:
            self.get_logger().info(f'{admission.reason} (sim restarted?): restarting the '
                                   'integration, pose kept', throttle_duration_sec=5.0)
        # Published on joint_states time, not a timer: in a lockstep sim every run publishes
        # the same poses, and a consumer can wait for the odom of a given state.
        if due:
            self._publish(msg.stamp)

    def _publish(self, stamp) -> None:
        odometry = self._odometry
        msg = self._odom
        orientation = yaw_quaternion(odometry.yaw)
        msg.pack(0, stamp.sec, stamp.nanosec)
        msg.pack(1, odometry.x, odometry.y, 0.0, *orientation)
        msg.pack(3, odometry.v, 0.0, 0.0, 0.0, 0.0, odometry.omega)
        self._odom_pub.publish(msg.serialized())
        if self._tf_pub is not None:
            transform = self._transform
            transform.pack(0, stamp.sec, stamp.nanosec)
            transform.pack(1, odometry.x, odometry.y, 0.0, *orientation)
            self._tf_pub.publish(transform.serialized())

    def _on_reset(self, request: Empty.Request, response: Empty.Response) -> Empty.Response:
        self._odometry.reset()
        self.get_logger().info('odometry reset to the origin')
        return response

    def _on_set_pose(self, request: SetPose2D.Request,
                     response: SetPose2D.Response) -> SetPose2D.Response:
        try:
            self._odometry.set_pose(request.x, request.y, request.yaw)
        except ValueError as error:
            response.success = False
            response.message = f'pose refused: {error}'
            return response
        response.success = True
        response.message = f'pose set to ({request.x}, {request.y}, {request.yaw})'
        return response


def main(args=None) -> None:
    sys.exit(run_node(OdometryNode, 'odometry', args))


if __name__ == '__main__':
    main()
