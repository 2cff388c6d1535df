"""
How a signal ends ``run_node``, the Jazzy main loop every node runs.

rclpy's handlers pass SIGINT on to Python, which raises KeyboardInterrupt wherever the main
thread is. Inside the EventsExecutor, pybind11 turns it into a RuntimeError ("Unable to
convert call argument '0' to Python object") while the context is still up: the controller
ended with it and exit 1 once in CI (tests/test_signals.py).
"""

import os
import subprocess
import sys

from swivel_car_testing import next_domain_id

NODE = """
import os
import signal
import sys
import time

from rclpy.node import Node
from rclpy.signals import uninstall_signal_handlers
from swivel_car_ros.ros_params import run_node


class SignalledNode(Node):

    def __init__(self):
        super().__init__('signalled')
        # The context stays up after the signal, as when rclpy's signal thread (which shuts
        # it down) had not run yet on the loaded CI machine.
        uninstall_signal_handlers()
        self.create_timer(0.01, self.on_timer)

    def on_timer(self):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5.0)
        except KeyboardInterrupt:
            # As pybind11 reports a KeyboardInterrupt while converting a callback's argument.
            raise RuntimeError("Unable to convert call argument '0' to Python object")


sys.exit(run_node(SignalledNode, 'signalled'))
"""


def test_a_signal_turned_into_another_error_inside_a_callback_ends_the_node_with_exit_0():
    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain_id()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    result = subprocess.run([sys.executable, '-c', NODE], capture_output=True, text=True,
                            timeout=60.0, env=env)
    assert result.returncode == 0, result.stderr
    assert 'Traceback' not in result.stderr, result.stderr


RACED_SHUTDOWN = """
import os
import signal
import sys

from rclpy.context import Context
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from swivel_car_ros.ros_params import run_node


def raced(context):
    # As when rclpy's signal thread shut the context down between try_shutdown's check and
    # its own shutdown.
    raise _rclpy.RCLError('failed to shutdown: rcl_shutdown already called on the given '
                          'context')


class SignalledNode(Node):

    def __init__(self):
        super().__init__('signalled')
        self.create_timer(0.01, lambda: os.kill(os.getpid(), signal.SIGINT))


Context.try_shutdown = raced
sys.exit(run_node(SignalledNode, 'signalled'))
"""


def test_a_shutdown_raced_by_rclpys_signal_thread_ends_the_node_with_exit_0():
    """Seen once in CI: the recorder ended a SIGINT with a traceback and exit 1."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain_id()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    result = subprocess.run([sys.executable, '-c', RACED_SHUTDOWN], capture_output=True,
                            text=True, timeout=60.0, env=env)
    assert result.returncode == 0, result.stderr
    assert 'Traceback' not in result.stderr, result.stderr
