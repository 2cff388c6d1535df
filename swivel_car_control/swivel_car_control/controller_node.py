"""
controller_node: swivel PID, cmd_vel and swivel_command handling.

One ActuatorCommand per joint_states message (the lockstep protocol of docs/architecture.md).
"""

from __future__ import annotations

import dataclasses
import sys
import time

from builtin_interfaces.msg import Time as TimeMsg
from geometry_msgs.msg import Twist, TwistStamped
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import Header
from swivel_car_control.core.controller import ControllerConfig, SwivelController
from swivel_car_control.core.joint_states import JointStateController
from swivel_car_control.joints import MissingJointError
from swivel_car_model.checks import check_nonempty_string, check_number
from swivel_car_model.description import described
from swivel_car_msgs.msg import ActuatorCommand, SwivelCommand, SwivelControllerState
from swivel_car_ros.lockstep import ChainedAnswers, stamp_ns
from swivel_car_ros.ros_params import (
    declare_dataclass, declare_description, is_zero_stamp, live_parameters, run_node,
    stamp_to_seconds, STATE_QUEUE_DEPTH)
from swivel_car_ros.serialized import (
    JointStateView, read_joint_state, read_logged, SerializedMessage, STAMP_FORMAT)

# A cmd_vel stamped further than this ahead of the node clock is taken as arriving now.
_CLOCK_SLACK = 0.5  # [s]
_NO_STAMP = TimeMsg()  # a source's stamp in the controller state while none was heard


@dataclasses.dataclass(frozen=True)
class ControllerNodeConfig:
    """
    What the node alone reads: its topics' types, frames and the lockstep chain's waits.

    Each field's metadata ``description`` (with its unit) is also its ROS parameter's.

    Raises
    ------
    ValueError
        A field is of the wrong type or out of range; the message names it.

    """

    use_stamped: bool = described(True, 'cmd_vel is geometry_msgs/TwistStamped (true) or Twist')
    base_frame_id: str = described('base_link', 'frame of ~/cmd_vel_out (REP-105 base_link)')
    swivel_joint: str = described('swivel_joint', 'name of the swivel joint in joint_states')
    lockstep_swivel_command: bool = described(
        False, 'lockstep sim with a stamped swivel_command stream (the planner): answer each '
        'joint_states only once the command answering the previous one has come, so climbs do '
        'not depend on machine load')
    lockstep_cmd_vel: bool = described(
        False, 'lockstep sim with a driver that answers every state with a cmd_vel stamped '
        "with it (a test or benchmark driver): wait for that cmd_vel as for the planner's "
        'command; not for a teleop, which publishes at its own rate')
    lockstep_wait: float = described(
        0.05, 'longest wall-time wait for that command; then answer without it and wait no '
        "more until the next command; keep it below the sim's lockstep_timeout [s]")

    def __post_init__(self) -> None:
        for name in ('base_frame_id', 'swivel_joint'):
            check_nonempty_string(name, getattr(self, name))
        check_number('lockstep_wait', self.lockstep_wait, above=0.0, unit='s')


class ControllerNode(Node):
    """Event-driven swivel car controller; see the package README for its interface."""

    def __init__(self, **kwargs) -> None:
        super().__init__('controller', **kwargs)
        robot = declare_description(self)
        car = robot.model_params()
        config = declare_dataclass(self, ControllerConfig,
                                   given={'max_torque': robot.swivel_torque_limit})
        self._node_config = node = declare_dataclass(self, ControllerNodeConfig)
        self._core = SwivelController(car, config)
        live_parameters(self, ControllerConfig.LIVE,
                        lambda changes: dataclasses.replace(self._core.config, **changes),
                        self._core.reconfigure)
        self._joint_states = JointStateController(self._core, node.swivel_joint)
        self._warned_zero_stamp = False
        # When to answer a joint_states in the lockstep chain: docs/architecture.md.
        self._chain: ChainedAnswers[JointStateView] = ChainedAnswers(
            round(node.lockstep_wait * 1e9), node.lockstep_swivel_command,
            node.lockstep_cmd_vel)

        # Built once, refilled every period: a message constructor imports and builds each
        # nested message in Python, every time; the command is rewritten in its CDR bytes.
        self._command = SerializedMessage(ActuatorCommand(), (
            (STAMP_FORMAT, ('header.stamp.sec', 'header.stamp.nanosec')),
            ('<2d', ('swivel_torque', 'drive_speed'))))
        self._answered_command = b''  # the command of the last state answered in full
        self._state = SwivelControllerState()
        self._limited = TwistStamped()
        self._limited.header.frame_id = node.base_frame_id
        self._command_pub = self.create_publisher(ActuatorCommand, 'actuator_command',
                                                  STATE_QUEUE_DEPTH)
        self._state_pub = self.create_publisher(SwivelControllerState, '~/controller_state',
                                                STATE_QUEUE_DEPTH)
        self._cmd_out_pub = self.create_publisher(TwistStamped, '~/cmd_vel_out', 10)
        self.create_subscription(JointState, 'joint_states', self._on_joint_states, 10,
                                 raw=True)
        self.create_subscription(TwistStamped if node.use_stamped else Twist, 'cmd_vel',
                                 self._on_cmd_vel, 10)
        self.create_subscription(SwivelCommand, 'swivel_command', self._on_swivel_command, 10)
        self.create_subscription(Header, 'sim/reset_event', self._on_sim_reset, 10)
        if node.lockstep_swivel_command or node.lockstep_cmd_vel:
            self.create_timer(node.lockstep_wait / 4.0, self._on_wait_timer,
                              clock=Clock(clock_type=ClockType.STEADY_TIME))
        self.get_logger().info(
            f'controller up: swivel limit {self._core.swivel_limit:.3f} rad (tip-safe), '
            f'kp={car.kp} ki={car.ki} kd={car.kd}, cmd_vel as '
            f'{"TwistStamped" if node.use_stamped else "Twist"}, '
            f'deadman {config.cmd_vel_timeout} s'
            + (', lockstep with swivel_command' if node.lockstep_swivel_command else '')
            + (', lockstep with cmd_vel' if node.lockstep_cmd_vel else ''))

    def _now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9  # [s]

    def _cmd_vel_time(self, stamp) -> float:
        """
        Return a cmd_vel stamp in seconds of the node clock [s].

        A zero stamp or one from another clock counts as now.
        """
        now = self._now()
        seconds = stamp_to_seconds(stamp)
        if is_zero_stamp(stamp):
            if not self._warned_zero_stamp:
                self.get_logger().warn(
                    'cmd_vel has a zero stamp: using the node clock (warned once)')
                self._warned_zero_stamp = True
            return now
        if seconds > now + _CLOCK_SLACK:
            # A stamp from another clock (wall time against sim time) would never expire.
            self.get_logger().warn(
                f'cmd_vel stamp is {seconds - now:.1f} s ahead of the node clock (clock '
                'mismatch? use_sim_time?): using the node clock', throttle_duration_sec=5.0)
            return now
        if 0.0 < self._core.config.cmd_vel_timeout < now - seconds:
            self.get_logger().warn(
                f'cmd_vel stamp is {now - seconds:.1f} s old, beyond cmd_vel_timeout: the '
                'deadman ignores it (clock mismatch? use_sim_time?)', throttle_duration_sec=5.0)
        return seconds

    def _on_cmd_vel(self, msg: TwistStamped | Twist) -> None:
        if isinstance(msg, TwistStamped):
            twist = msg.twist
            header_stamp = msg.header.stamp
            stamp = self._cmd_vel_time(header_stamp)
        else:
            twist = msg
            header_stamp = _NO_STAMP
            stamp = self._now()
        try:
            self._core.set_cmd_vel(twist.linear.x, twist.angular.z, stamp)
        except ValueError as error:
            self.get_logger().warn(str(error))
        # In the chain or out of it, whether the core took it or not.
        self._answer(self._chain.heard(self._chain.driver, stamp_ns(header_stamp), True,
                                       self._holding(), header_stamp))

    def _on_swivel_command(self, msg: SwivelCommand) -> None:
        held_before = self._holding()
        applied = False
        try:
            # The deadman counts from receipt: a planner that lags behind a lockstep sim
            # running ahead of it (before its first command held the sim back) is not dead.
            # Receipt is after the last state answered: its stamp, exact where the node clock
            # moves in steps of a thinned /clock (the in-process stack takes the same).
            received = self._joint_states.last_time
            self._core.set_swivel_command(msg.angle, msg.max_rate, msg.drive_speed, msg.hold,
                                          self._now() if received is None else received,
                                          msg.free)
        except ValueError as error:
            self.get_logger().error(str(error), throttle_duration_sec=1.0)
        else:
            applied = True
            if msg.hold and not held_before:
                self.get_logger().info(
                    f'swivel_command takes over: angle {msg.angle:.3f} rad, drive '
                    f'{msg.drive_speed:.3f} rad/s')
            elif held_before and not msg.hold:
                self.get_logger().info('swivel_command released: cmd_vel steers again')
        self._answer(self._chain.heard(self._chain.planner, stamp_ns(msg.header.stamp),
                                       applied, self._holding(), msg.header.stamp))

    def _holding(self) -> bool:
        """Tell whether a swivel_command is held: the planner's next one is awaited."""
        return self._core.swivel_command is not None

    def _on_sim_reset(self, msg: Header) -> None:
        t = stamp_to_seconds(msg.stamp)
        try:
            self._joint_states.reset(t)
        except ValueError as error:
            self.get_logger().warn(f'ignoring sim/reset_event: {error}',
                                   throttle_duration_sec=1.0)
            return
        self._chain.forget(stamp_ns(msg.stamp))
        self.get_logger().info(f'the sim was reset at {t:.3f} s: commands dropped, the swivel '
                               'held where it is measured then, drive stopped, until a new '
                               'command')

    def _on_wait_timer(self) -> None:
        msg, late = self._chain.tick(self._holding(), time.monotonic_ns())
        if late:
            names = ' or '.join(source.name for source in late)
            self.get_logger().warn(
                f'no {names} answered the last state within lockstep_wait '
                f'{self._node_config.lockstep_wait} s: going on without it until the next one '
                'comes (the run is no longer deterministic)', throttle_duration_sec=5.0)
        self._answer(msg)

    def _on_joint_states(self, data: bytes) -> None:
        msg = read_logged(self.get_logger(), read_joint_state, data, 'joint_states')
        if msg is None:
            return
        self._answer(self._chain.state(stamp_ns(msg.stamp), msg, self._holding(),
                                       time.monotonic_ns()))

    def _publish_command(self, stamp: TimeMsg, swivel_torque: float,
                         drive_speed: float) -> bytes:
        """Publish one ActuatorCommand; return it serialized."""
        command = self._command
        command.pack(0, stamp.sec, stamp.nanosec)
        command.pack(1, swivel_torque, drive_speed)
        serialized = command.serialized()
        self._command_pub.publish(serialized)
        return serialized

    def _answer(self, msg: JointStateView | None) -> None:
        """One ActuatorCommand (and controller state) for this joint_states; None: none."""
        if msg is None:
            return
        stamp = msg.stamp
        if self._chain.repeats(stamp_ns(stamp)):  # the sim's copy of the state answered
            self._command_pub.publish(self._answered_command)
            return
        try:
            swivel, out = self._joint_states.answer(
                stamp_to_seconds(stamp), msg.name, msg.position, msg.velocity)
        except MissingJointError as error:
            # Still answer the stamp (the lockstep sim waits for it), with the safe command.
            self.get_logger().warn(f'{error}: commanding zero torque and drive',
                                   throttle_duration_sec=5.0)
            self._publish_command(stamp, 0.0, 0.0)
            return
        if out.cmd_vel_timed_out:
            self.get_logger().info('cmd_vel timed out: drive stopped, swivel held',
                                   throttle_duration_sec=10.0)
        if out.swivel_command_timed_out:
            self.get_logger().warn('swivel_command timed out (planner gone?): released, drive '
                                   'stopped, swivel held')
        self._answered_command = self._publish_command(stamp, out.swivel_torque, out.drive_speed)

        state = self._state
        state.header.stamp = stamp
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
        planner, driver = self._chain.planner, self._chain.driver
        state.swivel_command_stamp = (_NO_STAMP if planner.heard_stamp is None
                                      else planner.heard_stamp)
        state.cmd_vel_stamp = _NO_STAMP if driver.heard_stamp is None else driver.heard_stamp
        self._state_pub.publish(state)
        self._chain.answered(stamp_ns(stamp))

        # A diagnostic: published only to a listener (a recorder that subscribes gets it).
        if self._cmd_out_pub.get_subscription_count():
            limited = self._limited
            limited.header.stamp = stamp
            limited.twist.linear.x = out.v_out
            limited.twist.angular.z = out.omega_out
            self._cmd_out_pub.publish(limited)


def main(args=None) -> None:
    sys.exit(run_node(ControllerNode, 'controller', args))


if __name__ == '__main__':
    main()
