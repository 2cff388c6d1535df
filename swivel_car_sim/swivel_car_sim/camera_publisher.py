"""
The sim node's depth camera on ROS: its parameters, its image and camera_info topics.

It publishes what a RealSense driver would (REP 118): ``camera/depth/image_rect_raw``
(sensor_msgs/Image, 32FC1 in metres, NaN for no return) and ``camera/depth/camera_info``
(plumb_bob, no distortion) with the same stamp, in the optical frame, with sensor-data QoS
(best effort, keep last 5). A frame is rendered only while someone subscribes to the image.
"""

from __future__ import annotations

import array

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import CameraInfo, Image
from swivel_car_model.description import CarDescription
from swivel_car_sim.depth_camera import CameraConfig, DepthCamera, PARAMETERS
from swivel_car_sim.sensor_models import StereoDepthNoise

IMAGE_TOPIC = 'camera/depth/image_rect_raw'
INFO_TOPIC = 'camera/depth/camera_info'


class CameraPublisher:
    """
    The depth camera of a sim node.

    Parameters
    ----------
    node : Node
        The sim node: declares the camera's parameters (read-only) and publishes.
    client : int
        The pybullet client of the world.
    description : CarDescription
    control_period : float  # [s]

    Raises
    ------
    ValueError
        A bad camera parameter, in one line.

    """

    def __init__(self, node: Node, client: int, description: CarDescription,
                 control_period: float) -> None:
        for name, (default, text) in PARAMETERS.items():
            node.declare_parameter(name, default, ParameterDescriptor(
                description=text, dynamic_typing=True, read_only=True))
        self.config = CameraConfig.from_values(
            {name: node.get_parameter(name).value for name in PARAMETERS}, control_period)
        self._node = node
        self._last_stamp = -1  # [ns]
        if self.config.rate == 0.0:
            return
        self._every = self.config.periods_per_frame(control_period)
        self.camera = DepthCamera(client, description, self.config.width, self.config.height,
                                  StereoDepthNoise() if self.config.noise else None,
                                  self.config.seed)
        self._image_pub = node.create_publisher(Image, IMAGE_TOPIC, qos_profile_sensor_data)
        self._info_pub = node.create_publisher(CameraInfo, INFO_TOPIC, qos_profile_sensor_data)
        k = self.camera.intrinsics
        self._info = CameraInfo(height=k.height, width=k.width, distortion_model='plumb_bob',
                                d=[0.0] * 5, k=k.k, r=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0,
                                                       1.0],
                                p=[k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0])
        self._info.header.frame_id = self.config.frame_id

    def after_period(self, periods: int, state, sec: int, nanosec: int) -> None:
        """
        Publish a frame if ``periods`` (control periods so far) is a frame's and it is heard.

        ``state`` is the sim's RobotState at the stamp ``sec``, ``nanosec``.
        """
        stamp = sec * 1_000_000_000 + nanosec  # [ns]
        if (self.config.rate == 0.0 or periods % self._every or stamp == self._last_stamp
                or not self._image_pub.get_subscription_count()):
            return
        self._last_stamp = stamp
        depth = self.camera.capture(state.position, state.orientation, stamp)
        image = Image(height=depth.shape[0], width=depth.shape[1], encoding='32FC1',
                      is_bigendian=0, step=depth.shape[1] * 4)
        image.header.stamp.sec, image.header.stamp.nanosec = sec, nanosec
        image.header.frame_id = self.config.frame_id
        # An array.array: assigning bytes checks every element in Python (common_interfaces#177).
        image.data = array.array('B', depth.astype('<f4').tobytes())
        self._info.header.stamp = image.header.stamp
        self._image_pub.publish(image)
        self._info_pub.publish(self._info)
