"""
foxglove_bridge_node: a live view of the stack in Foxglove.

Needs no RViz or ROS install on the viewing machine. Serves every topic of the graph (as they
appear) over Foxglove's WebSocket protocol with the Foxglove SDK, as ``ros2msg`` schemas and CDR
messages, the way the recorder writes them, so a bag and the live view open alike. The car's
frames are the stack's own ``/tf`` (the odometry's odom -> base_link, robot_description_node's
links) and ``/tf_static`` (transient local: the last message is sent to each new subscriber),
which Foxglove's 3D panel reads as it reads them from a bag.

Open Foxglove, "Open connection", ``ws://localhost:8765``.
"""

from __future__ import annotations

import sys

from ament_index_python.packages import get_package_share_directory
import foxglove
from foxglove import Channel, Schema
from foxglove.websocket import ChannelView, Client, ServerListener
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy

from swivel_car_ros.ros_params import refuse_runtime_changes, run_node
from swivel_car_telemetry.bag import MessageDefinitions, UnknownTypeError
from swivel_car_telemetry.topics import message_class, subscription_qos, TopicWatcher

PARAMETERS = {
    'host': ('127.0.0.1', "address to serve on; '0.0.0.0' for other machines"),
    'port': (8765, 'WebSocket port'),
    'discovery_period': (0.5, 'how often the graph is searched for new topics [s] wall'),
}


class _Latching(ServerListener):
    """
    Sender of the last message of a latched (transient local) topic to each new subscriber.

    As a ROS late subscriber would get it.
    """

    def __init__(self) -> None:
        self.last: dict[int, tuple[Channel, bytes, int]] = {}

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        if channel.id in self.last:
            stored, data, log_time = self.last[channel.id]
            stored.log(data, log_time=log_time)


class FoxgloveBridgeNode(Node):
    """The Foxglove WebSocket bridge; see the bringup package README."""

    def __init__(self, **kwargs) -> None:
        super().__init__('foxglove_bridge', **kwargs)
        values = {name: self.declare_parameter(
            name, default, ParameterDescriptor(description=text)).value
            for name, (default, text) in PARAMETERS.items()}
        refuse_runtime_changes(self, set(PARAMETERS))
        if not 0 <= values['port'] <= 65535:
            raise ValueError(f'port must be in 0..65535, got {values["port"]}')
        self._definitions = MessageDefinitions(get_package_share_directory)
        self._latching = _Latching()
        try:
            self._server = foxglove.start_server(
                name='swivel_car', host=values['host'], port=values['port'],
                server_listener=self._latching)
        except RuntimeError as error:
            raise ValueError(f'cannot serve on {values["host"]}:{values["port"]}: {error}') \
                from None
        self._channels: list[Channel] = []
        TopicWatcher(self, self._on_topic, values['discovery_period'])
        self.get_logger().info(f'Foxglove: open ws://{values["host"]}:{self._server.port}')

    def _on_topic(self, topic: str, type_name: str, publishers: list) -> None:
        try:
            msg_class = message_class(type_name)
            msgdef, _ = self._definitions.definition(type_name)
        except (LookupError, UnknownTypeError) as error:
            self.get_logger().error(f'not serving {topic}: {error}')
            return
        channel = Channel(topic, message_encoding='cdr', schema=Schema(
            name=type_name, encoding='ros2msg', data=msgdef.encode()))
        self._channels.append(channel)
        qos = subscription_qos(publishers)
        latched = qos.durability == DurabilityPolicy.TRANSIENT_LOCAL

        def forward(data: bytes) -> None:
            log_time = self.get_clock().now().nanoseconds
            if latched:
                # Kept before it is sent: a client subscribing in between (on the server's
                # thread) then gets it from on_subscribe; kept after, it got it from neither.
                self._latching.last[channel.id()] = (channel, data, log_time)
            channel.log(data, log_time=log_time)

        self.create_subscription(msg_class, topic, forward, qos, raw=True)
        self.get_logger().info(f'serving {topic} ({type_name})')

    def destroy_node(self) -> None:
        self._server.stop()
        super().destroy_node()


def main(args=None) -> None:
    sys.exit(run_node(FoxgloveBridgeNode, 'foxglove_bridge', args))


if __name__ == '__main__':
    main()
