"""
recorder_node: records every topic of the stack into a rosbag2 bag with MCAP storage.

Topics are recorded as they appear on the graph, ``/clock`` included, each message stamped
with its time of receipt on the node's clock (sim time with ``use_sim_time``), as ``ros2 bag
record`` does.

Stopping (SIGINT, SIGTERM) loses nothing the node has received: the callback under way
finishes (the signal is not raised inside it, where it would drop the message or leave a
half-written record in the .mcap), then the messages still queued in the subscriptions (the
recorder may lag the publishers by many) are written before the bag is closed.
"""

from __future__ import annotations

from pathlib import Path
import sys
import time

from ament_index_python.packages import get_package_share_directory
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosbags.interfaces import (
    Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime)

from swivel_car_ros.ros_params import refuse_runtime_changes, run_node
from swivel_car_telemetry.bag import BagWriter, MessageDefinitions, UnknownTypeError
from swivel_car_telemetry.topics import DEFAULT_EXCLUDED, message_class, subscription_qos, \
    TopicWatcher

PARAMETERS = {
    'output': ('', "bag directory to create; '' = rosbag2_<date>_<time> in the working "
                   'directory'),
    'topics': (Parameter.Type.STRING_ARRAY, 'topics to record; unset = every topic but '
                                            'exclude_topics'),
    'exclude_topics': (list(DEFAULT_EXCLUDED), 'topics not recorded when topics is empty'),
    'discovery_period': (0.5, 'how often the graph is searched for new topics [s] wall'),
    'min_free_space': (64.0, 'stop and close the bag when the disk has less free [MB]'),
}


def _time(duration) -> QosTime:
    return QosTime(*divmod(duration.nanoseconds, 1_000_000_000))


def _offered_qos(publishers) -> list[Qos]:
    """Return the publishers' QoS as rosbag2 stores them, so `ros2 bag play` offers the same."""
    return [Qos(QosHistory(p.history.value), p.depth, QosReliability(p.reliability.value),
                QosDurability(p.durability.value), _time(p.deadline), _time(p.lifespan),
                QosLiveliness(p.liveliness.value), _time(p.liveliness_lease_duration), False)
            for p in (info.qos_profile for info in publishers)]


class RecorderNode(Node):
    """The bag recorder; see the bringup package README."""

    def __init__(self, **kwargs) -> None:
        super().__init__('recorder', **kwargs)
        values = {name: self.declare_parameter(
            name, default, ParameterDescriptor(description=text)).value
            for name, (default, text) in PARAMETERS.items()}
        refuse_runtime_changes(self, set(PARAMETERS))
        output = values['output'] or time.strftime('rosbag2_%Y_%m_%d-%H_%M_%S')
        self._bag = BagWriter(Path(output).absolute(),
                              MessageDefinitions(get_package_share_directory),
                              int(values['min_free_space'] * 1e6))
        self._watcher = TopicWatcher(
            self, self._on_topic, values['discovery_period'],
            values['topics'] or (), values['exclude_topics'])
        self._stop_reported = False
        self.get_logger().info(f'recording to {self._bag.path} once a topic appears')

    def _on_topic(self, topic: str, type_name: str, publishers: list) -> None:
        if self._bag.stopped is not None:
            return
        try:
            msg_class = message_class(type_name)
            if not self._bag.is_open:
                self._bag.create()
            self._bag.add_topic(topic, type_name, _offered_qos(publishers))
        except (LookupError, UnknownTypeError) as error:
            self.get_logger().error(f'not recording {topic}: {error}')
            return
        except OSError as error:
            self._bag.stopped = f'cannot create the bag: {error}'
            self.get_logger().error(f'NOT recording: {self._bag.stopped}')
            return
        self.create_subscription(
            msg_class, topic, lambda data, topic=topic: self._on_message(topic, data),
            subscription_qos(publishers), raw=True)
        self.get_logger().info(f'recording {topic} ({type_name})')

    def _on_message(self, topic: str, data: bytes) -> None:
        if not self._bag.write(topic, self.get_clock().now().nanoseconds, data) \
                and not self._stop_reported:
            self.get_logger().error(f'recording stopped: {self._bag.stopped}; the bag is '
                                    f'closed: {self._bag.path}')
            self._stop_reported = True

    def drain(self) -> int:
        """
        Handle the messages already queued in the subscriptions; return how many.

        ``/clock`` included, so that they are stamped with the latest time; as the executor
        would, one per subscription in turn; the spin has ended. At most a queue's depth
        each, so that a publisher still going cannot keep the node from closing.
        """
        taken = 0
        budget = {sub: max(sub.qos_profile.depth, 1) for sub in self.subscriptions}
        while budget:
            for sub in list(budget):
                with sub.handle:
                    received = sub.handle.take_message(sub.msg_type, sub.raw)
                budget[sub] -= 1
                if received is None or budget[sub] == 0:
                    del budget[sub]
                if received is not None:
                    sub.callback(received[0])
                    taken += 1
        return taken

    def destroy_node(self) -> None:
        queued = 0
        try:
            queued = self.drain()
        except Exception as error:  # the bag must still be closed
            self.get_logger().error(f'writing the queued messages failed: {error!r}')
        try:
            records = self._bag.close()
        except OSError as error:
            self.get_logger().error(f'closing {self._bag.path} failed: {error}')
        else:
            if records:
                total = sum(r.count for r in records)
                self.get_logger().info(f'closed {self._bag.path}: {total} messages on '
                                       f'{len(records)} topics ({queued} queued at the stop)')
        super().destroy_node()


def main(args=None) -> None:
    # run_node ends the spin after the callback under way on a signal, so that no
    # KeyboardInterrupt lands inside a write; destroy_node drains the queues and closes the bag.
    sys.exit(run_node(RecorderNode, 'recorder', args))


if __name__ == '__main__':
    main()
