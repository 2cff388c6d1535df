"""
Subscribing to whatever the graph offers, as ``ros2 bag record -a`` does.

Shared by the recorder and the Foxglove bridge.
"""

from __future__ import annotations

import importlib
from typing import Callable, Iterable

from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.topic_endpoint_info import TopicEndpointInfo

# Infrastructure every node has; not the stack's data.
DEFAULT_EXCLUDED = ('/rosout', '/parameter_events')
QUEUE_DEPTH = 1000  # [messages] a burst the subscriber may fall behind by without a loss


def message_class(type_name: str) -> type:
    """
    Return the Python class of a message type.

    The type is named as e.g. 'sensor_msgs/msg/JointState' or an action's
    'swivel_car_msgs/action/ClimbStep_FeedbackMessage'.

    Raises
    ------
    LookupError
        Not importable.

    """
    try:
        package, kind, name = type_name.split('/')
        module = importlib.import_module(f'{package}.{kind}')
    except (ValueError, ImportError) as error:
        raise LookupError(f'{type_name}: {error}') from None
    found = getattr(module, name, None)
    if found is None and kind == 'action' and '_' in name:
        action, _, part = name.partition('_')
        found = getattr(getattr(getattr(module, action, None), 'Impl', None), part, None)
    if found is None:
        raise LookupError(f'{type_name}: no such type in {package}.{kind}')
    return found


def subscription_qos(publishers: Iterable[TopicEndpointInfo]) -> QoSProfile:
    """
    Return a QoS that hears every publisher and gets what a transient local one keeps.

    Reliable and transient local only when all publishers offer it (rosbag2's adaptive QoS).
    """
    profiles = [info.qos_profile for info in publishers]
    reliable = bool(profiles) and all(
        p.reliability == ReliabilityPolicy.RELIABLE for p in profiles)
    latched = bool(profiles) and all(
        p.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in profiles)
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST, depth=QUEUE_DEPTH,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)


class TopicWatcher:
    """
    Watcher that calls ``on_topic(topic, type_name, publishers)`` once for each new topic.

    Each topic that appears on the graph with a publisher, checked every ``period`` wall
    seconds (sim time may stand still). A topic with several types is reported once in the
    log and left out.

    Parameters
    ----------
    node : Node
    on_topic : callable
    period : float
        [s] wall time between looks at the graph.
    topics : iterable of str
        Only these (fully qualified names); empty: every topic but ``excluded``.
    excluded : iterable of str

    """

    def __init__(self, node: Node, on_topic: Callable[[str, str, list], None], period: float,
                 topics: Iterable[str] = (), excluded: Iterable[str] = DEFAULT_EXCLUDED) -> None:
        if not period > 0.0:
            raise ValueError(f'discovery_period must be > 0 s, got {period!r}')
        self._node = node
        self._on_topic = on_topic
        self._only = {node.resolve_topic_name(t) for t in topics}
        self._excluded = {node.resolve_topic_name(t) for t in excluded}
        self._seen: set[str] = set()
        self._timer = node.create_timer(period, self.look,
                                        clock=Clock(clock_type=ClockType.STEADY_TIME))

    def look(self) -> None:
        """Report the topics that are new since the last look."""
        for topic, types in self._node.get_topic_names_and_types():
            if topic in self._seen or topic in self._excluded or (
                    self._only and topic not in self._only):
                continue
            publishers = self._node.get_publishers_info_by_topic(topic)
            if not publishers:
                continue
            self._seen.add(topic)
            if len(types) != 1:
                self._node.get_logger().error(
                    f'{topic} has several types ({", ".join(types)}): left out')
                continue
            self._on_topic(topic, types[0], publishers)
