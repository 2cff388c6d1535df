"""
ROS glue shared by the nodes: config dataclasses as parameters, the main loop, stamps.

Parameters the ROS 2 way: each is read-only (``ros2 param set`` prints "Trying to set a
read-only parameter") unless its node applies it while running (``live_parameters``); a live
one set to a bad value is refused with the reason.
"""

from __future__ import annotations

import dataclasses
import math
import signal
import typing
from typing import Any, Callable, Collection, Mapping, TypeVar

from builtin_interfaces.msg import Time
from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
import rclpy
from rclpy.exceptions import ParameterException
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from swivel_car_model import description
from swivel_car_model.description import CarDescription

T = TypeVar('T')

# State messages kept on both ends (publisher history, subscription queue): joint_states, so
# that a node outside the lockstep chain (the odometry) that lags behind an unpaced sim skips no
# state, and what a recorder or a test watches (ground truth, odom, actuator commands,
# controller states; 10 kept are too few for a recorder under load): 1 s of the default control
# period. Not more: Fast DDS keeps a writer's history in a 512 KiB shared-memory segment.
STATE_QUEUE_DEPTH = 100


def stamp_to_seconds(stamp: Time) -> float:
    """Convert a builtin_interfaces/Time to seconds [s]."""
    return stamp.sec + stamp.nanosec * 1e-9


def is_zero_stamp(stamp: Time) -> bool:
    """Tell whether ``stamp`` is zero: unset, or no such moment."""
    return stamp.sec == 0 and stamp.nanosec == 0


def moment_seconds(stamp: Time) -> float:
    """Return ``stamp`` in seconds [s], -inf for the zero stamp (no such moment yet)."""
    return -math.inf if is_zero_stamp(stamp) else stamp_to_seconds(stamp)


def declare_dataclass(node: Node, cls: type[T], given: Mapping[str, Any] | None = None) -> T:
    """
    Declare one parameter per field of ``cls`` and build it from their values.

    The fields are ``swivel_car_model.description.described``: each one's default and
    description (with its unit) are its parameter's, its validation the dataclass's. A
    parameter has its field's type: a ``float`` field's is dynamically typed, so that an
    integer passes (``kp:=19``), and the dataclass checks it; a ``bool``, ``int`` or ``str``
    field's is of that type (``max_misses:=3`` is the integer 3, ``use_stamped:=7`` is refused
    naming it); another field's (a tuple of numbers) is dynamically typed, as a list.

    The fields in ``given`` (stated elsewhere) are not declared. All are read-only but the
    fields ``cls.LIVE`` names (if it has that class attribute), which its node applies while
    running.

    Raises
    ------
    ValueError
        The dataclass refuses the values; the message names the field.
    ParameterException
        A value of another type than its ``bool``, ``int`` or ``str`` field's.

    """
    values = dict(given or {})
    live = getattr(cls, 'LIVE', ())
    types = typing.get_type_hints(cls)
    for field in dataclasses.fields(cls):
        if field.name in values:
            continue
        kind, default = types[field.name], field.default
        if kind is float:
            default = float(default)
        value = node.declare_parameter(
            field.name, list(default) if isinstance(default, tuple) else default,
            ParameterDescriptor(description=field.metadata['description'],
                                dynamic_typing=kind not in (bool, int, str),
                                read_only=field.name not in live)).value
        values[field.name] = tuple(value) if isinstance(default, tuple) else value
    return cls(**values)


def declare_description(node: Node) -> CarDescription:
    """
    Declare the robot description as read-only parameters.

    The same names and defaults in every node (``swivel_car_model.description``).

    Raises
    ------
    ValueError
        A value the description refuses; the message names the parameter.

    """
    return CarDescription.from_values({
        name: node.declare_parameter(
            name, default, ParameterDescriptor(description=text, dynamic_typing=True,
                                               read_only=True)).value
        for name, (default, text) in description.PARAMETERS.items()})


def refuse_runtime_changes(node: Node, names: set[str]) -> None:
    """Parameters are read once at start: refuse later changes with a clear reason."""

    def callback(parameters: list) -> SetParametersResult:
        changed = sorted(p.name for p in parameters if p.name in names)
        if changed:
            return SetParametersResult(
                successful=False,
                reason=f'{", ".join(changed)} are read at start-up; restart the node to change')
        return SetParametersResult(successful=True)

    node.add_on_set_parameters_callback(callback)


def live_parameters(node: Node, names: Collection[str], check: Callable[[dict[str, Any]], T],
                    apply: Callable[[T], None]) -> None:
    """
    Make the parameters ``names`` apply while the node runs.

    ``check`` builds what a set of them means (their new values by name) or raises
    ``ValueError``, which refuses the set with its message as the reason; once set,
    ``apply`` takes what ``check`` built.
    """

    def changes(parameters: list) -> dict[str, Any]:
        return {p.name: p.value for p in parameters if p.name in names}

    def validate(parameters: list) -> SetParametersResult:
        try:
            check(changes(parameters))
        except ValueError as error:
            return SetParametersResult(successful=False, reason=str(error))
        return SetParametersResult(successful=True)

    def commit(parameters: list) -> None:
        changed = changes(parameters)
        if changed:
            apply(check(changed))
            node.get_logger().info(
                'set ' + ', '.join(f'{name} = {value!r}' for name, value in changed.items()))

    node.add_on_set_parameters_callback(validate)
    node.add_post_set_parameters_callback(commit)


def run_node(node_class: type[Node], name: str, args: list[str] | None = None,
             executor_class: Callable[[], Executor] = EventsExecutor) -> int:
    """
    Run the Jazzy main loop for one node.

    A refused parameter ends it with a clear error, a signal (Ctrl-C, SIGTERM) quietly once
    the callback in progress, if any, has returned.

    Returns the process exit code (0, or 1 for a configuration error).
    """
    signals: list[int] = []

    def on_signal(signum: int, frame) -> None:
        # Only noted: the loop ends after the callback in progress, on a context still up.
        # rclpy's own handlers shut the context down from their thread under a running
        # callback, whose publish then fails, and a KeyboardInterrupt raised in a callback
        # fails it too; the EventsExecutor logs either as FATAL with a stack (SIGTERM included).
        # A second signal interrupts as usual: a stuck shutdown (a bag's close) still ends.
        signals.append(signum)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)

    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, on_signal)
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    node = executor = None
    try:
        node = node_class()
        # EventsExecutor: a message hop in a quarter of the SingleThreadedExecutor's time,
        # which is most of a lockstep period. A signal's handler runs once spin_once returns.
        executor = executor_class()
        executor.add_node(node)
        while rclpy.ok() and not signals:
            executor.spin_once(timeout_sec=0.1)
    except ExternalShutdownException:
        pass
    except (ValueError, ParameterException) as error:
        rclpy.logging.get_logger(name).fatal(f'bad configuration: {error}')
        return 1
    finally:
        # The executor first: an EventsExecutor torn down by the garbage collector after its
        # node's entities are gone aborts the process ('Destroying callback manager with
        # callbacks remaining'), seen once on a recorder stopped while it subscribed.
        if executor is not None:
            executor.shutdown()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
