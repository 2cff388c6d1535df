"""
RobotState -> ROS messages (thin, no logic beyond field mapping).

The node publishes four messages every control period; building them fresh costs more than
a physics step, so it keeps one message of each type (``StateMessages``) and refills it.
"""

from __future__ import annotations

from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState

from swivel_car_sim.physics import RobotState


def sim_time_msg(steps: int, time_step_ns: int) -> Time:
    """Stamp of a sim time given as whole physics steps (exact, no float rounding)."""
    nanoseconds = steps * time_step_ns
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


class StateMessages:
    """One /clock, joint_states, imu and ground_truth/odom message, refilled from states."""

    def __init__(self, joint_names: tuple[str, ...], world_frame_id: str = 'world',
                 base_frame_id: str = 'base_link') -> None:
        self.clock = Clock()
        self.joint_state = JointState()
        self.joint_state.name = list(joint_names)
        self.imu = Imu()
        self.imu.header.frame_id = base_frame_id
        self.odometry = Odometry()
        self.odometry.header.frame_id = world_frame_id
        self.odometry.child_frame_id = base_frame_id

    def fill(self, state: RobotState, stamp: Time, imu: bool, odometry: bool) -> None:
        """
        Refill the messages (imu and odometry only when asked) with ``state`` at ``stamp``.

        Ground truth: pose of the base frame in the world frame, twist in the base frame.
        """
        self.clock.clock = stamp
        js = self.joint_state
        js.header.stamp = stamp
        js.position = state.positions.tolist()
        js.velocity = state.velocities.tolist()
        js.effort = state.efforts.tolist()
        qx, qy, qz, qw = state.orientation.tolist()
        if imu:
            m = self.imu
            m.header.stamp = stamp
            o = m.orientation
            o.x, o.y, o.z, o.w = qx, qy, qz, qw
            w = m.angular_velocity
            w.x, w.y, w.z = state.angular_velocity.tolist()
            a = m.linear_acceleration
            a.x, a.y, a.z = state.linear_acceleration.tolist()
        if odometry:
            m = self.odometry
            m.header.stamp = stamp
            pose = m.pose.pose
            pose.position.x, pose.position.y, pose.position.z = state.position.tolist()
            o = pose.orientation
            o.x, o.y, o.z, o.w = qx, qy, qz, qw
            twist = m.twist.twist
            twist.linear.x, twist.linear.y, twist.linear.z = state.linear_velocity.tolist()
            twist.angular.x, twist.angular.y, twist.angular.z = state.angular_velocity.tolist()
