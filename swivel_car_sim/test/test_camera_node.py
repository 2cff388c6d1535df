"""The sim node's depth camera on ROS, in process with real rclpy, as a RealSense driver's."""

import math
import os

import numpy as np
import pytest
import rclpy
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import CameraInfo, Image
from std_srvs.srv import SetBool
from swivel_car_msgs.srv import StepSimulation
from swivel_car_sim.camera_publisher import IMAGE_TOPIC, INFO_TOPIC
from swivel_car_sim.sim_node import SimNode
from swivel_car_testing import next_domain_id, spin_until

TIMEOUT = 20.0  # [s] wall guard against a hang, not a measurement


class Rig:
    """A paused sim node and a client subscribed to the camera, in a fresh domain."""

    def __init__(self, **parameters) -> None:
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
        namespace = f'/camera_test_{os.getpid()}'
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=next_domain_id())
        self.sim = SimNode(context=self.context, namespace=namespace, parameter_overrides=[
            Parameter(name, value=value) for name, value in
            {'start_paused': True, **parameters}.items()])
        self.client = Node('camera_client', namespace=namespace, context=self.context)
        self.executor = EventsExecutor(context=self.context)
        self.executor.add_node(self.sim)
        self.executor.add_node(self.client)
        self.images, self.infos = [], []
        self.client.create_subscription(Image, IMAGE_TOPIC, self.images.append,
                                        qos_profile_sensor_data)
        self.client.create_subscription(CameraInfo, INFO_TOPIC, self.infos.append,
                                        qos_profile_sensor_data)

    def step(self, steps: int) -> None:
        client = self.client.create_client(StepSimulation, 'sim/step')
        spin_until(self.executor, client.service_is_ready, TIMEOUT, 'sim/step')
        future = client.call_async(StepSimulation.Request(steps=steps))
        spin_until(self.executor, future.done, TIMEOUT, 'sim/step response')
        assert future.result().success, future.result().message

    def close(self) -> None:
        self.executor.shutdown()
        self.sim.destroy_node()
        self.client.destroy_node()
        rclpy.try_shutdown(context=self.context)


def test_depth_image_and_camera_info_as_a_realsense_driver_publishes_them():
    rig = Rig(camera_width=106, camera_height=60)
    try:
        spin_until(rig.executor, lambda: rig.sim.count_subscribers(
            f'{rig.sim.get_namespace()}/{IMAGE_TOPIC}') > 0, TIMEOUT, 'discovery')
        rig.step(100)  # 0.2 s: 20 control periods, two frames at 10 Hz
        spin_until(rig.executor, lambda: len(rig.images) >= 2 and len(rig.infos) >= 2,
                   TIMEOUT, 'two frames')
    finally:
        rig.close()
    image, info = rig.images[-1], rig.infos[-1]
    assert (image.header.stamp.sec, image.header.stamp.nanosec) == (0, 200_000_000)
    assert info.header.stamp == image.header.stamp
    assert image.header.frame_id == info.header.frame_id == 'camera_depth_optical_frame'
    assert (image.encoding, image.width, image.height, image.step, image.is_bigendian) == \
        ('32FC1', 106, 60, 106 * 4, 0)
    assert (info.width, info.height, info.distortion_model, list(info.d)) == \
        (106, 60, 'plumb_bob', [0.0] * 5)
    fy = 30.0 / math.tan(math.radians(29.0))  # [px] 58 deg over 60 rows
    assert list(info.k) == pytest.approx([fy, 0.0, 53.0, 0.0, fy, 29.0, 0.0, 0.0, 1.0])
    depth = np.frombuffer(bytes(image.data), dtype='<f4').reshape(60, 106)
    assert np.isnan(depth[0]).all(), 'sky: no return'
    # The rows around the optical axis (0.35 rad down from 0.25 m up) see ground about 0.7 m
    # away; the car's own front is in the bottom rows.
    assert 0.5 < np.nanmedian(depth[25:35]) < 1.0


def test_camera_off_publishes_nothing_and_a_bad_rate_is_refused():
    rig = Rig(camera_rate=0.0)
    try:
        assert rig.sim.count_publishers(f'{rig.sim.get_namespace()}/{IMAGE_TOPIC}') == 0
        paused = rig.client.create_client(SetBool, 'sim/set_paused')
        assert paused is not None
    finally:
        rig.close()
    with pytest.raises(ValueError, match='sim: invalid parameter: camera_rate must divide'):
        Rig(camera_rate=3.0)
