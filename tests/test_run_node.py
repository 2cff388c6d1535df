"""
How a signal ends ``run_node``, the Jazzy main loop every node runs.

With rclpy's own signal handlers, a signal shut the context down from rclpy's thread under a
running callback, whose next publish failed; a KeyboardInterrupt raised inside a callback
failed it too. The EventsExecutor logs such a failure as FATAL with a stack: the controller
did so on SIGTERM in tests/test_signals.py.
"""

import os
import signal
import subprocess
import sys

import pytest
from swivel_car_testing import next_domain_id

NODE = """
import os
import sys
import time

from std_msgs.msg import Empty
from rclpy.node import Node
from swivel_car_ros.ros_params import run_node


class SignalledNode(Node):

    def __init__(self):
        super().__init__('signalled')
        self.publisher = self.create_publisher(Empty, 'signalled', 10)
        self.create_timer(0.01, self.on_timer)
        self.signalled = False

    def on_timer(self):
        if not self.signalled:
            self.signalled = True
            os.kill(os.getpid(), {signum})
            time.sleep(0.5)  # room for a signal thread to shut the context down
        self.publisher.publish(Empty())
        print('published after the signal', flush=True)


sys.exit(run_node(SignalledNode, 'signalled'))
"""


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM],
                         ids=lambda s: signal.Signals(s).name)
def test_a_signal_inside_a_callback_lets_it_publish_and_ends_the_node_quietly(signum):
    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain_id()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    result = subprocess.run([sys.executable, '-c', NODE.format(signum=int(signum))],
                            capture_output=True, text=True, timeout=60.0, env=env)
    output = result.stdout + result.stderr
    assert result.returncode == 0, output
    assert 'published after the signal' in result.stdout, output
    for sign in ('Traceback', 'FATAL', 'Error occurred'):
        assert sign not in output, output
