"""
The controller node's deadmans hold whatever its clock does (issue 12).

Before, a runtime `ros2 param set /controller use_sim_time false` mid-drive, then the cmd_vel
publisher stopped, left the car driving (1.35 m in 5 s); one /clock of 2^31-1 s, then a held
swivel_command, left it moving 5.3 s later (deadman 0.5 s).
"""

import os

from builtin_interfaces.msg import Time
from geometry_msgs.msg import TwistStamped
import pytest
import rclpy
from rclpy.experimental import EventsExecutor
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from swivel_car_control.controller_node import ControllerNode
from swivel_car_msgs.msg import ActuatorCommand, SwivelCommand
from swivel_car_testing import next_domain_id, spin_until

TIMEOUT = 0.5  # [s] both deadmans
PERIOD = 0.01  # [s]


def stamp(t):
    return Time(sec=int(t), nanosec=int(round((t - int(t)) * 1e9)))


class Rig:
    """The controller on sim time, fed joint_states and /clock by hand, one period a step."""

    def __init__(self):
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
        rclpy.init(args=['--ros-args', '-p', 'use_sim_time:=true',
                         '-p', f'cmd_vel_timeout:={TIMEOUT}',
                         '-p', f'swivel_command_timeout:={TIMEOUT}'],
                   domain_id=next_domain_id())
        self.node = ControllerNode()
        self.probe = rclpy.create_node('probe')
        self.executor = EventsExecutor()
        self.executor.add_node(self.node)
        self.executor.add_node(self.probe)
        self.commands = []
        self.probe.create_subscription(ActuatorCommand, 'actuator_command',
                                       self.commands.append, 100)
        self.clock = self.probe.create_publisher(Clock, '/clock', 10)
        self.joints = self.probe.create_publisher(JointState, 'joint_states', 10)
        self.cmd_vel = self.probe.create_publisher(TwistStamped, 'cmd_vel', 10)
        self.swivel = self.probe.create_publisher(SwivelCommand, 'swivel_command', 10)
        spin_until(self.executor, lambda: all(
            p.get_subscription_count() > 0
            for p in (self.clock, self.joints, self.cmd_vel, self.swivel)), 10.0, 'subscriptions')
        self.t = 5.0

    def publish(self, publisher, msg):
        publisher.publish(msg)
        for _ in range(5):
            self.executor.spin_once(timeout_sec=0.002)

    def step(self, seconds=PERIOD, clock=True):
        """Advance sim time by ``seconds``, one joint_states a period; the last command."""
        for _ in range(int(round(seconds / PERIOD))):
            self.t += PERIOD
            if clock:
                self.publish(self.clock, Clock(clock=stamp(self.t)))
            count = len(self.commands)
            msg = JointState(name=['swivel_joint'], position=[0.0], velocity=[0.0])
            msg.header.stamp = stamp(self.t)
            self.joints.publish(msg)
            spin_until(self.executor, lambda: len(self.commands) > count, 10.0, 'command')
        return self.commands[-1]

    def close(self):
        self.executor.shutdown()
        self.probe.destroy_node()
        self.node.destroy_node()
        rclpy.try_shutdown()


@pytest.fixture
def rig():
    rig = Rig()
    yield rig
    rig.close()


def drive(rig):
    """cmd_vel as `ros2 topic pub` sends it (zero stamp: the controller stamps it) for 1 s."""
    msg = TwistStamped()
    msg.twist.linear.x = 0.3
    for _ in range(10):
        rig.publish(rig.cmd_vel, msg)
        command = rig.step(0.1)
    assert command.drive_speed > 0.0
    return msg


def test_a_use_sim_time_flip_mid_drive_does_not_stretch_the_cmd_vel_deadman(rig):
    msg = drive(rig)
    result = rig.node.set_parameters([Parameter('use_sim_time', Parameter.Type.BOOL, False)])
    assert result[0].successful
    rig.publish(rig.cmd_vel, msg)  # now stamped with wall time by the controller
    # The deadman, then the drive's deceleration limit (0.3 m/s at 1 m/s^2).
    assert rig.step(TIMEOUT + 0.3 + 0.05).drive_speed == 0.0
    assert rig.step(1.0).drive_speed == 0.0


def test_a_clock_far_ahead_does_not_stretch_the_swivel_command_deadman(rig):
    rig.step(0.1)
    rig.publish(rig.clock, Clock(clock=stamp(2.0**31 - 1)))
    rig.publish(rig.swivel, SwivelCommand(angle=0.0, drive_speed=3.0, hold=True))
    assert rig.step(0.1, clock=False).drive_speed > 0.0
    assert rig.step(TIMEOUT + 0.3).drive_speed == 0.0
    assert rig.step(1.0).drive_speed == 0.0


def test_a_clock_in_steps_does_not_shorten_the_swivel_command_deadman(rig):
    rig.step(0.1)
    rig.step(0.09, clock=False)  # /clock thinned to 10 Hz: the node clock 0.09 s behind
    rig.publish(rig.swivel, SwivelCommand(angle=0.0, drive_speed=3.0, hold=True))
    speeds = [rig.step(clock=False).drive_speed for _ in range(round((TIMEOUT - 0.02) / PERIOD))]
    # Held throughout, the drive only ramps up; timed out early, it would ramp down.
    assert speeds == sorted(speeds) and speeds[-1] > 0.0
    assert rig.step(0.3, clock=False).drive_speed < speeds[-1]  # then it does time out
