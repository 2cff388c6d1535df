"""The sim's serialized messages against the messages built field by field."""

from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState
from swivel_car_msgs.msg import ActuatorCommand
from swivel_car_sim.conversions import (
    actuator_command_fields, sim_time, sim_time_msg, StateMessages)
from swivel_car_sim.robot_state import RobotState

JOINTS = ('swivel_joint', 'rear_left_wheel_joint', 'rear_right_wheel_joint',
          'front_left_wheel_joint', 'front_right_wheel_joint')


def _state(seed: int) -> RobotState:
    rng = np.random.default_rng(seed)
    orientation = rng.normal(size=4)
    return RobotState(
        time=0.0, joint_names=JOINTS, positions=rng.normal(size=5),
        velocities=rng.normal(size=5), efforts=rng.normal(size=5), position=rng.normal(size=3),
        orientation=orientation / np.linalg.norm(orientation),
        linear_velocity=rng.normal(size=3), angular_velocity=rng.normal(size=3),
        linear_acceleration=rng.normal(size=3))


def _expected(state: RobotState, stamp: Time, world: str, base: str) -> dict:
    """Build the four messages field by field with the ROS message API."""
    joint_state = JointState(name=list(JOINTS), position=state.positions.tolist(),
                             velocity=state.velocities.tolist(), effort=state.efforts.tolist())
    joint_state.header.stamp = stamp
    qx, qy, qz, qw = state.orientation.tolist()
    imu = Imu()
    imu.header.stamp, imu.header.frame_id = stamp, base
    o = imu.orientation
    o.x, o.y, o.z, o.w = qx, qy, qz, qw
    w = imu.angular_velocity
    w.x, w.y, w.z = state.angular_velocity.tolist()
    a = imu.linear_acceleration
    a.x, a.y, a.z = state.linear_acceleration.tolist()
    odometry = Odometry(child_frame_id=base)
    odometry.header.stamp, odometry.header.frame_id = stamp, world
    p = odometry.pose.pose.position
    p.x, p.y, p.z = state.position.tolist()
    o = odometry.pose.pose.orientation
    o.x, o.y, o.z, o.w = qx, qy, qz, qw
    v = odometry.twist.twist.linear
    v.x, v.y, v.z = state.linear_velocity.tolist()
    w = odometry.twist.twist.angular
    w.x, w.y, w.z = state.angular_velocity.tolist()
    return {'clock': Clock(clock=stamp), 'joint_state': joint_state, 'imu': imu,
            'odometry': odometry}


def test_state_messages_are_the_messages_built_field_by_field():
    messages = StateMessages(JOINTS, 'map', 'robot1/base_link')
    # Twice: rewriting the fields leaves nothing of the state before.
    for steps, seed in ((1_000_000_005, 1), (5, 2)):
        sec, nanosec = sim_time(steps, 2_000_000)
        assert sim_time_msg(steps, 2_000_000) == Time(sec=sec, nanosec=nanosec)
        state = _state(seed)
        expected = _expected(state, Time(sec=sec, nanosec=nanosec), 'map', 'robot1/base_link')
        # Compared as messages: CDR padding bytes are whatever the serializer left there.
        assert deserialize_message(messages.clock(sec, nanosec), Clock) == expected['clock']
        for name in ('joint_state', 'imu', 'odometry'):
            data = getattr(messages, name)(state, sec, nanosec)
            assert deserialize_message(data, type(expected[name])) == expected[name], name


@pytest.mark.parametrize('frame_id', ['', 'b', 'ba', 'bas', 'base', 'base_link'])
def test_an_actuator_command_reads_as_built(frame_id):
    msg = ActuatorCommand(swivel_torque=-2.5, drive_speed=3.25)
    msg.header.stamp.sec, msg.header.stamp.nanosec = 4, 30_000_000
    msg.header.frame_id = frame_id
    assert actuator_command_fields(serialize_message(msg)) == (4_030_000_000, -2.5, 3.25)
