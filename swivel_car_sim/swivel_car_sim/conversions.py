"""
RobotState -> serialized ROS messages and back from the command (field mapping only).

The node publishes four messages every control period. Handing rclpy a message object costs
it a conversion to C and a serialization per publish (15-35 us for an Odometry here, its
covariances the most), so each message is serialized once (``StateMessages``) and only the
bytes of the fields that change are rewritten (``swivel_car_ros.serialized``); rclpy publishes
bytes as they are.
"""

from __future__ import annotations

from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState
from swivel_car_msgs.msg import ActuatorCommand
from swivel_car_ros.lockstep import stamp_ns
from swivel_car_ros.serialized import MessageReader, SerializedMessage, STAMP_FORMAT

from swivel_car_sim.robot_state import RobotState


def sim_time(steps: int, time_step_ns: int) -> tuple[int, int]:
    """Return (sec, nanosec) of a sim time given as whole physics steps (exact, no float)."""
    return divmod(steps * time_step_ns, 1_000_000_000)


def sim_time_msg(steps: int, time_step_ns: int) -> Time:
    """Stamp of a sim time given as whole physics steps (exact, no float rounding)."""
    sec, nanosec = sim_time(steps, time_step_ns)
    return Time(sec=sec, nanosec=nanosec)


_ACTUATOR_COMMAND = MessageReader(ActuatorCommand, (
    'header.stamp.sec', 'header.stamp.nanosec', 'swivel_torque', 'drive_speed'))


def actuator_command_fields(data: bytes) -> tuple[int, float, float]:
    """
    Read a serialized swivel_car_msgs/ActuatorCommand.

    Returns its stamp [ns], swivel torque [N m] and drive speed [rad/s].

    Raises
    ------
    ValueError
        Not little-endian plain CDR.

    """
    sec, nanosec, swivel_torque, drive_speed = _ACTUATOR_COMMAND(data)
    return stamp_ns(Time(sec=sec, nanosec=nanosec)), swivel_torque, drive_speed


class StateMessages:
    """/clock, joint_states, imu and ground_truth/odom of a state, serialized."""

    def __init__(self, joint_names: tuple[str, ...], world_frame_id: str = 'world',
                 base_frame_id: str = 'base_link') -> None:
        joints = f'<{len(joint_names)}d'
        self._clock = SerializedMessage(Clock(), (
            (STAMP_FORMAT, ('clock.sec', 'clock.nanosec')),))
        joint_state = JointState(name=list(joint_names))
        self._joint_state = SerializedMessage(joint_state, (
            (STAMP_FORMAT, ('header.stamp.sec', 'header.stamp.nanosec')),
            (joints, ('position',)), (joints, ('velocity',)), (joints, ('effort',))))
        imu = Imu()
        imu.header.frame_id = base_frame_id
        self._imu = SerializedMessage(imu, (
            (STAMP_FORMAT, ('header.stamp.sec', 'header.stamp.nanosec')),
            ('<4d', tuple(f'orientation.{c}' for c in 'xyzw')),
            ('<3d', tuple(f'angular_velocity.{c}' for c in 'xyz')),
            ('<3d', tuple(f'linear_acceleration.{c}' for c in 'xyz'))))
        odometry = Odometry(child_frame_id=base_frame_id)
        odometry.header.frame_id = world_frame_id
        self._odometry = SerializedMessage(odometry, (
            (STAMP_FORMAT, ('header.stamp.sec', 'header.stamp.nanosec')),
            ('<7d', tuple(f'pose.pose.position.{c}' for c in 'xyz')
             + tuple(f'pose.pose.orientation.{c}' for c in 'xyzw')),
            ('<6d', tuple(f'twist.twist.linear.{c}' for c in 'xyz')
             + tuple(f'twist.twist.angular.{c}' for c in 'xyz'))))

    def clock(self, sec: int, nanosec: int) -> bytes:
        """rosgraph_msgs/Clock of the sim time (sec, nanosec)."""
        m = self._clock
        m.pack(0, sec, nanosec)
        return m.serialized()

    def joint_state(self, state: RobotState, sec: int, nanosec: int) -> bytes:
        """sensor_msgs/JointState of ``state``, stamped (sec, nanosec)."""
        m = self._joint_state
        m.pack(0, sec, nanosec)
        m.pack(1, *state.positions.tolist())
        m.pack(2, *state.velocities.tolist())
        m.pack(3, *state.efforts.tolist())
        return m.serialized()

    def imu(self, state: RobotState, sec: int, nanosec: int) -> bytes:
        """sensor_msgs/Imu of ``state`` (covariances 0: unknown), stamped (sec, nanosec)."""
        m = self._imu
        m.pack(0, sec, nanosec)
        m.pack(1, *state.orientation.tolist())
        m.pack(2, *state.angular_velocity.tolist())
        m.pack(3, *state.linear_acceleration.tolist())
        return m.serialized()

    def odometry(self, state: RobotState, sec: int, nanosec: int) -> bytes:
        """
        nav_msgs/Odometry, the ground truth of ``state``, stamped (sec, nanosec).

        Pose of the base frame in the world frame, twist in the base frame.
        """
        m = self._odometry
        m.pack(0, sec, nanosec)
        m.pack(1, *state.position.tolist(), *state.orientation.tolist())
        m.pack(2, *state.linear_velocity.tolist(), *state.angular_velocity.tolist())
        return m.serialized()
