"""The planner's readers of serialized inputs against rclpy's own serialization."""

from nav_msgs.msg import Odometry
import pytest
from rclpy.serialization import serialize_message
from sensor_msgs.msg import Imu
from swivel_car_msgs.msg import SwivelControllerState
from swivel_car_planner.conversions import controller_state_fields, imu_fields, odom_fields

# Frame ids of every length modulo 8: each puts the fields after them at another alignment.
FRAME_IDS = ['', 'o', 'od', 'odo', 'odom', 'odom_', 'odom_1', 'odom_12', 'base_footprint']


@pytest.mark.parametrize('frame_id', FRAME_IDS)
@pytest.mark.parametrize('child_frame_id', FRAME_IDS)
def test_odom_fields_are_the_messages(frame_id, child_frame_id):
    msg = Odometry()
    msg.header.stamp.sec, msg.header.stamp.nanosec = 123, 456_000_789
    msg.header.frame_id, msg.child_frame_id = frame_id, child_frame_id
    position, orientation = msg.pose.pose.position, msg.pose.pose.orientation
    position.x, position.y, position.z = 1.25, -2.5, 0.125
    orientation.x, orientation.y, orientation.z, orientation.w = 0.1, -0.2, 0.3, 0.9
    msg.pose.covariance = [float(i) for i in range(36)]
    msg.twist.twist.linear.x, msg.twist.twist.linear.y = 0.75, -9.0
    stamp, x, y, quaternion, speed = odom_fields(serialize_message(msg))
    assert (stamp.sec, stamp.nanosec) == (123, 456_000_789)
    assert (x, y, quaternion, speed) == (1.25, -2.5, (0.1, -0.2, 0.3, 0.9), 0.75)


@pytest.mark.parametrize('frame_id', FRAME_IDS)
def test_imu_fields_are_the_messages(frame_id):
    msg = Imu()
    msg.header.stamp.sec, msg.header.stamp.nanosec = 7, 10_000_000
    msg.header.frame_id = frame_id
    msg.orientation.x, msg.orientation.y, msg.orientation.z = 0.01, 0.2, -0.03
    msg.orientation.w = 0.97
    msg.orientation_covariance = [-1.0] * 9
    msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = 0.5, -0.25, 2.0
    msg.angular_velocity_covariance = [9.0] * 9
    stamp, quaternion, angular_velocity = imu_fields(serialize_message(msg))
    assert (stamp.sec, stamp.nanosec) == (7, 10_000_000)
    assert quaternion == (0.01, 0.2, -0.03, 0.97)
    assert angular_velocity == (0.5, -0.25, 2.0)


@pytest.mark.parametrize('frame_id', FRAME_IDS)
@pytest.mark.parametrize('source', ['', 'hold', 'cmd_vel', 'swivel_command'])
def test_controller_state_fields_are_the_messages(frame_id, source):
    msg = SwivelControllerState(set_point=0.25, target=9.0, measured=-1.0, measured_rate=0.5,
                                torque=-3.5, d_term=7.0, saturated=True, drive_speed=2.0,
                                source=source)
    msg.header.stamp.sec, msg.header.stamp.nanosec = 11, 20_000_000
    msg.header.frame_id = frame_id
    msg.swivel_command_stamp.sec, msg.swivel_command_stamp.nanosec = 10, 990_000_000
    msg.cmd_vel_stamp.sec = 5
    stamp, set_point, swivel, swivel_rate, torque, command_stamp = controller_state_fields(
        serialize_message(msg))
    assert (stamp.sec, stamp.nanosec) == (11, 20_000_000)
    assert (set_point, swivel, swivel_rate, torque) == (0.25, -1.0, 0.5, -3.5)
    assert (command_stamp.sec, command_stamp.nanosec) == (10, 990_000_000)


def test_another_encoding_is_refused():
    data = bytearray(serialize_message(Imu()))
    data[1] = 0  # big-endian
    with pytest.raises(ValueError, match='encapsulation 0000'):
        imu_fields(bytes(data))
