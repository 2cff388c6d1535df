"""
The odometry node never integrates a joint_states message it cannot trust, and says so.

Before (issue 12), one wheel rate of 1e300 or -1e12 with the car standing, or one stamp of
0 s, 1 s or 2^31-1 s while driving, moved the odom 0.2 m to 1e296 m, with nothing logged.
"""

import os

from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
import pytest
from rcl_interfaces.msg import Log
import rclpy
from rclpy.experimental import EventsExecutor
from sensor_msgs.msg import JointState
from swivel_car_control.odometry_node import OdometryNode
from swivel_car_model.description import CarDescription
from swivel_car_testing import next_domain_id, spin_until

NAMES = ['swivel_joint', 'rear_left_wheel_joint', 'rear_right_wheel_joint']
R = CarDescription().model_params().r  # [m]


def joint_state(t, wheel_rate):
    msg = JointState()
    msg.header.stamp = Time(sec=int(t), nanosec=int(round((t - int(t)) * 1e9)))
    msg.name = NAMES
    msg.position = [0.0, 0.0, 0.0]
    msg.velocity = [0.0, wheel_rate, wheel_rate]
    return msg


@pytest.fixture
def odometry():
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    rclpy.init(args=['--ros-args', '-p', 'enable_odom_tf:=false'], domain_id=next_domain_id())
    node = OdometryNode()
    probe = rclpy.create_node('probe')
    executor = EventsExecutor()
    executor.add_node(node)
    executor.add_node(probe)
    try:
        yield node, probe, executor
    finally:
        executor.shutdown()
        probe.destroy_node()
        node.destroy_node()
        rclpy.try_shutdown()


@pytest.mark.parametrize('wheel_rate, bad', [
    (0.0, joint_state(10.505, 1e300)), (0.0, joint_state(10.505, -1e12)),
    (2.0, joint_state(0.0, 2.0)), (2.0, joint_state(1.0, 2.0)),
    (2.0, joint_state(2.0**31 - 1, 2.0))])
def test_one_untrusted_joint_states_is_refused_with_a_warning(odometry, wheel_rate, bad):
    node, probe, executor = odometry
    odom, logs = [], []
    probe.create_subscription(Odometry, 'odom', odom.append, 200)
    probe.create_subscription(Log, '/rosout', logs.append, 200)
    joints = probe.create_publisher(JointState, 'joint_states', 200)
    spin_until(executor, lambda: joints.get_subscription_count() > 0, 10.0, 'subscription')
    messages = [joint_state(10.0 + 0.01 * k, wheel_rate) for k in range(101)]
    messages.insert(51, bad)
    for msg in messages:
        joints.publish(msg)
        for _ in range(3):
            executor.spin_once(timeout_sec=0.002)
    spin_until(executor, lambda: odom and odom[-1].header.stamp == messages[-1].header.stamp,
               10.0, 'odom of the last state')
    assert odom[-1].pose.pose.position.x == pytest.approx(wheel_rate * R * 1.0, abs=1e-9)
    spin_until(executor, lambda: any('joint_states refused' in log.msg for log in logs), 10.0,
               'the warning')
    warning = next(log for log in logs if 'joint_states refused' in log.msg)
    assert warning.level == Log.WARN and warning.name == 'odometry'
