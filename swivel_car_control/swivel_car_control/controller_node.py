"""controller_node: swivel PID, cmd_vel and swivel_command handling, one ActuatorCommand per
joint_states message (the lockstep protocol of docs/architecture.md)."""

from __future__ import annotations

import dataclasses
import sys

from geometry_msgs.msg import Twist, TwistStamped
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from sensor_msgs.msg import JointState
from swivel_car_msgs.msg import ActuatorCommand, SwivelCommand, SwivelControllerState

from swivel_car_control.conversions import is_zero_stamp, stamp_to_seconds
from swivel_car_control.core.controller import ControllerConfig, SwivelController
from swivel_car_control.gains import TUNED_GAINS
from swivel_car_control.joints import JointReader, MissingJointError
from swivel_car_control.ros_params import (
    declare_car_params, declare_dataclass, refuse_runtime_changes, run_node)

# A cmd_vel stamped further than this ahead of the node clock is taken as arriving now.
_CLOCK_SLACK = 0.5  # [s]

CONFIG_DESCRIPTIONS = {
    'max_torque': 'swivel torque clamp [N m]',
    'max_integral_torque': 'clamp on the PID integral contribution [N m]',
    'integral_band': 'the PID integrates only while |error| is below this [rad]',
    'swivel_limit': 'largest |swivel set point|, <= max_swivel_angle; reduced further to keep '
                    'the tip-over rule [rad]',
    'max_swivel_rate': 'swivel set-point rate limit [rad/s]',
    'max_linear_velocity': 'forward speed limit of base_link [m/s]',
    'max_linear_acceleration': 'forward acceleration limit [m/s^2]',
    'max_angular_velocity': 'yaw rate limit [rad/s]',
    'max_angular_acceleration': 'yaw acceleration limit [rad/s^2]',
    'cmd_vel_timeout': 'deadman: older cmd_vel stops the drive, holds the swivel; 0 disables [s]',
    'slowdown_start': 'swivel error below which the drive runs at full speed [rad]',
    'slowdown_stop': 'swivel error above which the drive stops; cos(error) between [rad]',
    'tip_over_margin': 'margin on thesis eq. 72, (pi - phi)/2 - theta1 >= margin [rad]',
}


class ControllerNode(Node):
    """Event-driven swivel car controller; see the package README for its interface."""

    def __init__(self) -> None:
        super().__init__('controller')
        car = declare_car_params(self, TUNED_GAINS)
        config = declare_dataclass(self, ControllerConfig, CONFIG_DESCRIPTIONS)
        self._use_stamped = self.declare_parameter(
            'use_stamped', True, ParameterDescriptor(
                description='cmd_vel is geometry_msgs/TwistStamped (true) or Twist')).value
        swivel_joint = self.declare_parameter(
            'swivel_joint', 'swivel_joint',
            ParameterDescriptor(description='name of the swivel joint in joint_states')).value
        refuse_runtime_changes(self, {f.name for f in dataclasses.fields(car)}
                               | {f.name for f in dataclasses.fields(config)}
                               | {'use_stamped', 'swivel_joint'})
        self._core = SwivelController(car, config)
        self._swivel_joint = swivel_joint
        self._joints = JointReader([swivel_joint])
        self._warned_zero_stamp = False
        self._last_time: float | None = None

        self._command_pub = self.create_publisher(ActuatorCommand, 'actuator_command', 10)
        self._state_pub = self.create_publisher(SwivelControllerState, '~/controller_state', 10)
        self._cmd_out_pub = self.create_publisher(TwistStamped, '~/cmd_vel_out', 10)
        self.create_subscription(JointState, 'joint_states', self._on_joint_states, 10)
        self.create_subscription(TwistStamped if self._use_stamped else Twist, 'cmd_vel',
                                 self._on_cmd_vel, 10)
        self.create_subscription(SwivelCommand, 'swivel_command', self._on_swivel_command, 10)
        self.get_logger().info(
            f'controller up: swivel limit {self._core.swivel_limit:.3f} rad (tip-safe), '
            f'kp={car.kp} ki={car.ki} kd={car.kd}, cmd_vel as '
            f'{"TwistStamped" if self._use_stamped else "Twist"}, '
            f'deadman {config.cmd_vel_timeout} s')

    def _on_cmd_vel(self, msg: TwistStamped | Twist) -> None:
        now = self.get_clock().now().nanoseconds * 1e-9
        if isinstance(msg, TwistStamped):
            twist = msg.twist
            stamp = stamp_to_seconds(msg.header.stamp)
            if is_zero_stamp(msg.header.stamp):
                if not self._warned_zero_stamp:
                    self.get_logger().warn(
                        'cmd_vel has a zero stamp: using the node clock (warned once)')
                    self._warned_zero_stamp = True
                stamp = now
            elif stamp > now + _CLOCK_SLACK:
                # A stamp from another clock (wall time against sim time) would never expire.
                self.get_logger().warn(
                    f'cmd_vel stamp is {stamp - now:.1f} s ahead of the node clock (clock '
                    'mismatch? use_sim_time?): using the node clock',
                    throttle_duration_sec=5.0)
                stamp = now
            elif 0.0 < self._core.config.cmd_vel_timeout < now - stamp:
                self.get_logger().warn(
                    f'cmd_vel stamp is {now - stamp:.1f} s old, beyond cmd_vel_timeout: the '
                    'deadman ignores it (clock mismatch? use_sim_time?)',
                    throttle_duration_sec=5.0)
        else:
            twist = msg
            stamp = now
        try:
            self._core.set_cmd_vel(twist.linear.x, twist.angular.z, stamp)
        except ValueError as error:
            self.get_logger().warn(str(error))

    def _on_swivel_command(self, msg: SwivelCommand) -> None:
        try:
            self._core.set_swivel_command(msg.angle, msg.max_rate, msg.drive_speed, msg.hold)
        except ValueError as error:
            self.get_logger().error(str(error))
            return
        self.get_logger().info(
            f'swivel_command: angle {msg.angle:.3f} rad, drive {msg.drive_speed:.3f} rad/s'
            if msg.hold else 'swivel_command released: cmd_vel steers again')

    def _on_joint_states(self, msg: JointState) -> None:
        t = stamp_to_seconds(msg.header.stamp)
        command = ActuatorCommand()
        command.header.stamp = msg.header.stamp
        if self._last_time is not None and t < self._last_time:
            self._joints.reset()
        try:
            swivel = self._joints.read(t, msg.name, msg.position, msg.velocity)[
                self._swivel_joint]
        except MissingJointError as error:
            # Still answer the stamp (the lockstep sim waits for it), with the safe command.
            self.get_logger().warn(f'{error}: commanding zero torque and drive',
                                   throttle_duration_sec=5.0)
            self._command_pub.publish(command)
            return
        self._last_time = t
        out = self._core.step(t, swivel.position, swivel.rate)
        if out.cmd_vel_timed_out:
            self.get_logger().info('cmd_vel timed out: drive stopped, swivel held',
                                   throttle_duration_sec=10.0)
        command.swivel_torque = out.swivel_torque
        command.drive_speed = out.drive_speed
        self._command_pub.publish(command)

        state = SwivelControllerState()
        state.header.stamp = msg.header.stamp
        state.set_point = out.set_point
        state.target = out.target
        state.measured = swivel.position
        state.measured_rate = swivel.rate
        state.error = out.set_point - swivel.position
        state.torque = out.swivel_torque
        state.p_term = out.pid.p_term
        state.i_term = out.pid.i_term
        state.d_term = out.pid.d_term
        state.saturated = out.pid.saturated
        state.drive_speed = out.drive_speed
        state.source = out.source
        self._state_pub.publish(state)

        limited = TwistStamped()
        limited.header.stamp = msg.header.stamp
        limited.header.frame_id = 'base_link'
        limited.twist.linear.x = out.v_out
        limited.twist.angular.z = out.omega_out
        self._cmd_out_pub.publish(limited)


def main(args=None) -> None:
    sys.exit(run_node(ControllerNode, 'controller', args))


if __name__ == '__main__':
    main()
