"""
step_detector_node: the nearest step ahead in the depth camera's images, on ``detected_step``.

A thin adapter around ``core.detector.StepDetector`` (one image) and ``core.fusion.StepTracker``
(the frames fused with ``odom``); see the package README.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
import sys
import time

from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import ColorRGBA
from swivel_car_model.checks import check_nonempty_string, check_number
from swivel_car_model.description import described
from swivel_car_msgs.msg import DetectedStep
from swivel_car_perception.core.detector import (
    Detection, DetectorConfig, Mount, StepDetector)
from swivel_car_perception.core.fusion import Pose2D, StepTracker
from swivel_car_perception.core.image import depth_from_fields, intrinsics_from_camera_info
from swivel_car_perception.core.perception import StepPerception
from swivel_car_ros.ros_params import declare_dataclass, declare_description, run_node
from visualization_msgs.msg import Marker, MarkerArray

IMAGE_TOPIC = 'camera/depth/image_rect_raw'
INFO_TOPIC = 'camera/depth/camera_info'
REFUSAL_INTERVAL = 5.0  # [s] wall time between two lines about one kind of refusal


@dataclass(frozen=True)
class StepDetectorConfig:
    """The node's parameters (descriptions: each field's metadata)."""

    base_frame_id: str = described(
        'base_link', 'frame of detected_step and the markers (REP-105 base_link)')
    min_height: float = described(
        0.012, 'lowest step reported: raised points are this much above the ground [m]')
    max_distance: float = described(
        2.2, "farthest step edge reported, from the front axle's ground contact [m]")
    max_lateral: float = described(
        2.0, "points farther aside than this from base_link's x axis are left out [m]")
    odom_drift: float = described(
        0.02, 'odometry drift per metre driven (1 sigma) that the fused estimate allows [1]')
    gate: float = described(
        5.0, 'a detection further than this many sigmas from the fused estimate starts a new one '
        '[1]')
    max_misses: int = described(
        3, 'frames without a detection before the fused estimate is dropped [1]')

    def __post_init__(self) -> None:
        check_nonempty_string('base_frame_id', self.base_frame_id)
        for name in ('min_height', 'max_distance', 'max_lateral', 'odom_drift', 'gate'):
            check_number(name, getattr(self, name), above=0.0)
        check_number('max_misses', self.max_misses, at_least=0)
        if not isinstance(self.max_misses, int):
            raise ValueError(f'max_misses must be a whole number, got {self.max_misses!r}')


class StepDetectorNode(Node):
    """The step detector on the depth camera; see the package README for its interface."""

    def __init__(self, **kwargs) -> None:
        super().__init__('step_detector', **kwargs)
        robot = declare_description(self)
        self._config = config = declare_dataclass(self, StepDetectorConfig)
        self._mount = Mount.of(robot)
        self._detector_config = DetectorConfig(
            min_height=config.min_height, max_distance=config.max_distance,
            max_lateral=config.max_lateral)
        self._detector: StepDetector | None = None
        self._perception = StepPerception(None, StepTracker(
            robot.wheelbase, config.odom_drift, config.gate, config.max_misses))
        self._next_refusal: dict[str, float] = {}  # kind -> wall time [s] its next line is due
        self._step_pub = self.create_publisher(DetectedStep, 'detected_step', 10)
        self._marker_pub = self.create_publisher(MarkerArray, '~/markers', 10)
        self.create_subscription(CameraInfo, INFO_TOPIC, self._on_camera_info,
                                 qos_profile_sensor_data)
        self.create_subscription(Image, IMAGE_TOPIC, self._on_image, qos_profile_sensor_data)
        self.create_subscription(Odometry, 'odom', self._on_odom, 100)
        self.get_logger().info(
            f'step detector up: steps {config.min_height} m and higher, edges up to '
            f'{config.max_distance} m ahead of the front axle, on {IMAGE_TOPIC}')

    # --- inputs ----------------------------------------------------------------------------

    def _on_camera_info(self, info: CameraInfo) -> None:
        try:
            intrinsics = intrinsics_from_camera_info(info.width, info.height, info.k)
        except ValueError as error:
            self._refuse(f'refusing camera_info: {error}')
            return
        if self._detector is None or self._detector.intrinsics != intrinsics:
            self._detector = StepDetector(intrinsics, self._mount, self._detector_config)
            self._perception.detector = self._detector

    def _on_odom(self, odom: Odometry) -> None:
        q = odom.pose.pose.orientation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        stamp = odom.header.stamp.sec * 1_000_000_000 + odom.header.stamp.nanosec
        self._perception.odom(stamp, Pose2D(odom.pose.pose.position.x,
                                            odom.pose.pose.position.y, yaw))

    def _on_image(self, image: Image) -> None:
        if self._detector is None:
            self._refuse(f'refusing depth images: no camera_info yet on {INFO_TOPIC}')
            return
        try:
            depth = depth_from_fields(image.encoding, image.width, image.height, image.step,
                                      image.is_bigendian, bytes(image.data),
                                      self._detector.intrinsics)
        except ValueError as error:
            self._refuse(f'refusing depth image: {error}')
            return
        stamp = image.header.stamp.sec * 1_000_000_000 + image.header.stamp.nanosec
        detection, fused = self._perception.frame(depth, stamp)
        if not fused and detection.found:
            self.get_logger().warn('no odom at the image stamps: each frame on its own, '
                                   'unfused', throttle_duration_sec=10.0)
        if not detection.found:
            self.get_logger().debug(f'no step: {detection.reason}')
        self._publish(image, detection)

    def _refuse(self, line: str) -> None:
        """Log ``line``, at most once per REFUSAL_INTERVAL for its kind (its first words)."""
        kind, now = ' '.join(line.split()[:6]), time.monotonic()
        if now >= self._next_refusal.get(kind, -math.inf):
            self._next_refusal[kind] = now + REFUSAL_INTERVAL
            self.get_logger().warn(line)

    # --- outputs ---------------------------------------------------------------------------

    def _publish(self, image: Image, d: Detection) -> None:
        message = DetectedStep(found=d.found)
        message.header.stamp = image.header.stamp
        message.header.frame_id = self._config.base_frame_id
        if d.found:
            step = message.step
            step.height, step.depth, step.width = d.height, d.depth_seen, d.width
            step.distance, step.yaw = d.distance, d.yaw
            message.step_offset = d.offset
            message.height_std, message.distance_std = d.height_std, d.distance_std
            message.yaw_std, message.width_std = d.yaw_std, d.width_std
            message.left_end_seen, message.right_end_seen = d.left_end_seen, d.right_end_seen
        self._step_pub.publish(message)
        if self._marker_pub.get_subscription_count():
            self._marker_pub.publish(self._markers(message))

    def _markers(self, message: DetectedStep) -> MarkerArray:
        """Return the detected step as a box (RViz, Foxglove), deleted when none is found."""
        marker = Marker(header=message.header, ns='detected_step', id=0, type=Marker.CUBE)
        if not message.found:
            marker.action = Marker.DELETE
            return MarkerArray(markers=[marker])
        s = message.step
        depth = max(s.depth, 0.05)  # [m] at least a slab where the top was barely seen
        edge_x = self._mount.front_axle + s.distance  # [m] base_link x of the crossing
        cos_yaw, sin_yaw = math.cos(s.yaw), math.sin(s.yaw)
        centre_x = edge_x - message.step_offset * sin_yaw + depth / 2.0 * cos_yaw
        centre_y = message.step_offset * cos_yaw + depth / 2.0 * sin_yaw
        marker.action = Marker.ADD
        marker.pose.position.x, marker.pose.position.y = centre_x, centre_y
        marker.pose.position.z = s.height / 2.0 - self._mount.ground_height
        marker.pose.orientation.z, marker.pose.orientation.w = math.sin(s.yaw / 2.0), \
            math.cos(s.yaw / 2.0)
        marker.scale.x, marker.scale.y, marker.scale.z = depth, s.width, s.height
        both = message.left_end_seen and message.right_end_seen
        marker.color = ColorRGBA(r=0.1, g=0.8 if both else 0.5, b=0.2, a=0.6)
        return MarkerArray(markers=[marker])


def main(args=None) -> None:
    sys.exit(run_node(StepDetectorNode, 'step_detector', args))


if __name__ == '__main__':
    main()
