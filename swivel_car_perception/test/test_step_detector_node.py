"""The step detector node in process with real rclpy: detections, markers and refusals."""

import array
import os

import numpy as np
import pytest
from rcl_interfaces.msg import Log
import rclpy
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import CameraInfo, Image
from swivel_car_msgs.msg import DetectedStep
from swivel_car_perception.step_detector_node import (
    IMAGE_TOPIC, INFO_TOPIC, StepDetectorConfig, StepDetectorNode)
from swivel_car_testing import next_domain_id, spin_until
from synthetic_scene import depth_image, INTRINSICS
from visualization_msgs.msg import MarkerArray

TIMEOUT = 20.0  # [s] wall guard against a hang, not a measurement
STEP = (0.08, 0.9, 0.1, 1.0, 0.0, 1.0)  # height, distance, yaw, width, offset, depth


class Rig:
    """The detector and a test node playing the camera, on one executor."""

    def __init__(self) -> None:
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
        namespace = f'/detector_test_{os.getpid()}'
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=next_domain_id())
        self.detector = StepDetectorNode(context=self.context, namespace=namespace)
        self.client = Node('camera', namespace=namespace, context=self.context)
        self.executor = EventsExecutor(context=self.context)
        self.executor.add_node(self.detector)
        self.executor.add_node(self.client)
        self.steps, self.markers, self.logs = [], [], []
        self.client.create_subscription(Log, '/rosout', lambda log: self.logs.append(log.msg),
                                        100)
        self.client.create_subscription(DetectedStep, 'detected_step', self.steps.append, 10)
        self.client.create_subscription(MarkerArray, 'step_detector/markers',
                                        self.markers.append, 10)
        self.images = self.client.create_publisher(Image, IMAGE_TOPIC, qos_profile_sensor_data)
        self.infos = self.client.create_publisher(CameraInfo, INFO_TOPIC,
                                                  qos_profile_sensor_data)
        spin_until(self.executor, lambda: self.images.get_subscription_count() > 0
                   and self.infos.get_subscription_count() > 0
                   and self.detector.count_subscribers(f'{namespace}/detected_step') > 0,
                   TIMEOUT, 'discovery')

    def info(self, width=INTRINSICS.width, height=INTRINSICS.height) -> None:
        k = INTRINSICS
        self.infos.publish(CameraInfo(width=width, height=height, distortion_model='plumb_bob',
                                      k=[k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0]))

    def image(self, sec: int, depth: np.ndarray, encoding: str = '32FC1') -> None:
        message = Image(height=depth.shape[0], width=depth.shape[1], encoding=encoding,
                        step=depth.shape[1] * 4)
        message.header.stamp.sec = sec
        message.data = array.array('B', depth.astype('<f4').tobytes())
        self.images.publish(message)

    def logged(self, words: str) -> None:
        spin_until(self.executor, lambda: any(words in line for line in self.logs), TIMEOUT,
                   f'the log line {words!r}')

    def next_step(self, count: int) -> DetectedStep:
        spin_until(self.executor, lambda: len(self.steps) >= count, TIMEOUT, 'detected_step')
        return self.steps[count - 1]

    def close(self) -> None:
        self.executor.shutdown()
        self.detector.destroy_node()
        self.client.destroy_node()
        rclpy.try_shutdown(context=self.context)


@pytest.mark.parametrize('name, value, refusal', [
    ('min_height', -0.01, 'min_height must be a finite number > 0'),
    ('gate', float('nan'), 'gate must be a finite number > 0'),
    ('odom_drift', True, 'odom_drift must be a finite number > 0'),
    ('max_misses', -1, 'max_misses must be a finite number >= 0'),
    ('max_misses', 2.5, 'max_misses must be a whole number'),
    ('base_frame_id', '', 'base_frame_id must be a non-empty string')])
def test_a_bad_setting_is_refused_naming_it(name, value, refusal):
    with pytest.raises(ValueError, match=refusal):
        StepDetectorConfig(**{name: value})


@pytest.fixture(scope='module')
def rig():
    made = Rig()
    yield made
    made.close()


def test_refusals_then_a_step_and_its_marker(rig):
    scene = depth_image(STEP, noise_seed=4)
    rig.image(1, scene)
    rig.logged('refusing depth images: no camera_info yet')
    rig.info()
    spin_until(rig.executor, lambda: rig.detector._detector is not None, TIMEOUT, 'info')
    rig.image(2, scene, encoding='rgb8')
    rig.logged("refusing depth image: depth image encoding 'rgb8' is not a depth encoding")
    rig.image(3, scene[:60, :106])
    rig.logged('refusing depth image: depth image is 106x60 but its camera_info says 212x120')
    rig.image(4, scene)
    step = rig.next_step(1)
    # Only the fourth image was taken: the refused ones published nothing.
    assert step.header.stamp.sec == 4 and step.header.frame_id == 'base_link'
    assert step.found and step.left_end_seen and step.right_end_seen
    assert step.step.height == pytest.approx(0.08, abs=0.005)
    assert step.step.distance == pytest.approx(0.9, abs=0.015)
    assert step.step.yaw == pytest.approx(0.1, abs=0.02)
    assert step.step.width == pytest.approx(1.0, abs=0.05)
    assert 0.0 < step.distance_std < 0.01
    spin_until(rig.executor, lambda: rig.markers, TIMEOUT, 'markers')
    assert rig.markers[-1].markers[0].scale.z == pytest.approx(step.step.height)


def test_no_return_and_flat_ground_are_found_false(rig):
    before = len(rig.steps)
    rig.image(5, np.full((INTRINSICS.height, INTRINSICS.width), np.nan))
    blank = rig.next_step(before + 1)
    rig.image(6, depth_image(noise_seed=5))
    flat = rig.next_step(before + 2)
    assert (blank.header.stamp.sec, flat.header.stamp.sec) == (5, 6)
    assert not blank.found and not flat.found and flat.step.height == 0.0
