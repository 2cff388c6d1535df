"""
The sim node: the pybullet swivel car behind the topics of a motor driver board and an IMU.

It owns /clock and has a deterministic lockstep mode (docs/architecture.md); with
``clock_source:=wall`` it stamps with the system clock and runs at real time, as the hardware
does. Its sensors and links are ``sensor_profile``'s (``swivel_car_sim.sensor_models``).
"""

from __future__ import annotations

import dataclasses
import sys
import time

from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import Imu, JointState
from std_msgs.msg import Header
from std_srvs.srv import SetBool
from swivel_car_msgs.msg import ActuatorCommand
from swivel_car_msgs.srv import (RemoveObstacle, ResetSimulation, SpawnObstacle,
                                 StepSimulation)
from swivel_car_ros.lockstep import SimLockstep
from swivel_car_ros.ros_params import run_node, STATE_QUEUE_DEPTH
from swivel_car_ros.serialized import read_logged
from swivel_car_sim.camera_publisher import CameraPublisher
from swivel_car_sim.command_pace import CommandPace
from swivel_car_sim.config import PARAMETERS, SimNodeConfig
from swivel_car_sim.conversions import (
    actuator_command_fields, sim_time, sim_time_msg, StateMessages)
from swivel_car_sim.physics import MAX_STEPS_PER_CALL, SwivelCarSim
from swivel_car_sim.sensor_models import DelayedCommands, SensorSuite
from swivel_car_sim.wall_clock import MAX_LAG_NS, WallPacer
from swivel_car_sim.world import StepSpec

# With real_time_factor 0 one timer callback steps for at most this long, then yields to
# the executor so that commands and service calls are never starved.
FAST_BATCH_WALL_TIME = 0.005  # [s]
# With real_time_factor 0, how often a sim waiting (paused, or for its controller) looks
# whether it may run again; a command or a resume restarts it at once.
FAST_WAIT_PERIOD = 0.02  # [s] wall
# How the log says that the controller stopped answering, and that it answers again: a
# supervisor (or a test) reads them to tell whether the sim hears the controller.
LOCKSTEP_TIMED_OUT_LOG = 'lockstep: no actuator_command'
LOCKSTEP_RESUMED_LOG = 'lockstep: actuator_command again'
PACE_TIMED_OUT_LOG = 'free running: no actuator_command'


class SimNode(Node):
    """pybullet simulation of the swivel car (see the package README for the interface)."""

    def __init__(self, **kwargs) -> None:
        super().__init__('sim', **kwargs)
        # Read-only: the world is built from them at start. Dynamically typed so that an
        # integer where a number is due (mass:=21) passes; SimNodeConfig checks the types.
        for name, (default, description) in PARAMETERS.items():
            self.declare_parameter(name, default, ParameterDescriptor(
                description=description, dynamic_typing=True, read_only=True))
        try:
            self.config = SimNodeConfig.from_values(
                {name: self.get_parameter(name).value for name in PARAMETERS})
        except ValueError as error:
            raise ValueError(f'sim: invalid parameter: {error}') from error
        cfg = self.config
        self.sim = SwivelCarSim(cfg.physics, cfg.initial_pose)
        try:
            self._camera = CameraPublisher(self, self.sim.client, self.sim.description,
                                           cfg.control_period)
        except ValueError as error:
            self.sim.close()
            raise ValueError(f'sim: invalid parameter: {error}') from error
        self._time_step_ns = round(cfg.physics.time_step * 1e9)
        # When to advance (lockstep and pause): docs/architecture.md.
        self._lockstep = SimLockstep(
            round(cfg.control_period * 1e9), round(cfg.lockstep_timeout * 1e9),
            cfg.lockstep_real_time_factor, cfg.start_paused, time.monotonic_ns())
        self._periods = 0
        self._messages = StateMessages(self.sim.joint_names, cfg.world_frame_id,
                                       cfg.base_frame_id)
        # The hardware's faults: None for the ideal profile (the state as it is, commands
        # applied as they come).
        self._sensors = (None if cfg.sensors.ideal
                         else SensorSuite(cfg.sensors, cfg.sensor_seed, self.sim.state()))
        self._commands = DelayedCommands(cfg.physics.time_step)
        self._wall = (WallPacer(round(cfg.control_period * 1e9), 0, time.time_ns())
                      if cfg.wall_clock else None)
        # Free running on sim time: never ahead of the controller by more than
        # max_command_age (a board on the system clock waits for no one).
        self._pace = (CommandPace(round(cfg.max_command_age * 1e9),
                                  round(cfg.lockstep_timeout * 1e9), time.monotonic_ns())
                      if not (cfg.lockstep or cfg.wall_clock) else None)
        self._fast_timer = None

        self._clock_pub = self.create_publisher(ClockMsg, '/clock', 10)
        self._joint_pub = self.create_publisher(JointState, 'joint_states', STATE_QUEUE_DEPTH)
        self._imu_pub = self.create_publisher(Imu, 'imu', 10)
        self._odom_pub = self.create_publisher(Odometry, 'ground_truth/odom',
                                               STATE_QUEUE_DEPTH)
        self._reset_pub = self.create_publisher(Header, '~/reset_event', 10)
        self.create_subscription(ActuatorCommand, 'actuator_command', self._on_command, 10,
                                 raw=True)
        self.create_service(ResetSimulation, '~/reset', self._on_reset)
        self.create_service(SetBool, '~/set_paused', self._on_set_paused)
        self.create_service(StepSimulation, '~/step', self._on_step)
        self.create_service(StepSimulation, '~/run', self._on_run)
        self.create_service(SpawnObstacle, '~/spawn_obstacle', self._on_spawn)
        self.create_service(RemoveObstacle, '~/remove_obstacle', self._on_remove)

        wall = Clock(clock_type=ClockType.STEADY_TIME)
        if self._wall is not None:
            # Finer than a period, so that a late call is caught up by the next one.
            self.create_timer(0.5 * cfg.control_period, self._on_wall_timer, clock=wall)
        elif cfg.lockstep:
            self.create_timer(self._lockstep.tick_period_ns * 1e-9, self._on_lockstep_timer,
                              clock=wall)
        elif cfg.real_time_factor > 0.0:
            self.create_timer(cfg.control_period / cfg.real_time_factor, self._advance_if_running,
                              clock=wall)
        else:
            self._fast_timer = self.create_timer(0.0, self._on_fast_timer, clock=wall)
            self.create_timer(FAST_WAIT_PERIOD, self._wake_fast_timer, clock=wall)
        self._publish_state()
        self.get_logger().info(
            f'{cfg.physics.robot_variant} car, time_step {cfg.physics.time_step} s, control '
            f'period {cfg.control_period} s, '
            + ('lockstep' if cfg.lockstep else f'real_time_factor {cfg.real_time_factor}')
            + (', paused' if self._lockstep.paused else '')
            + (', wall clock (no /clock)' if self._wall is not None else '')
            + f', sensor profile {cfg.sensors.name}')

    def destroy_node(self) -> None:
        self.sim.close()
        super().destroy_node()

    # --- stepping --------------------------------------------------------------------------

    def _stamp_ns(self) -> int:
        """Return the stamp [ns] of the current state: its sim time, or the system clock's."""
        sim_ns = self.sim.steps * self._time_step_ns  # [ns]
        return sim_ns if self._wall is None else self._wall.stamp_ns(sim_ns)

    def _stamp(self):
        return Time(sec=self._stamp_ns() // 1_000_000_000,
                    nanosec=self._stamp_ns() % 1_000_000_000)

    def _step_physics(self, steps: int) -> None:
        """Step the physics, applying each delayed command at its physics step."""
        self._commands.step(self.sim, steps, self._apply)

    def _advance(self) -> None:
        """One control period of physics, then publish the new state."""
        while True:
            self._step_physics(self.config.steps_per_period)
            self._periods += 1
            now = time.monotonic_ns()  # [ns]
            stamp, lost = self._publish_messages()
            self._lockstep.advanced(stamp, now)
            # A lost state gets no answer: in lockstep the board goes on with the command it
            # has, as if answered, so that the chain stays deterministic.
            if not (lost and self.config.lockstep and self._lockstep.heard(stamp, now)):
                return

    def _advance_if_running(self) -> None:
        if not self._lockstep.paused and self._may_step():
            self._advance()

    def _may_step(self) -> bool:
        """Free running: tell whether the controller's newest command lets the sim step on."""
        if self._pace is None:
            return True
        timed_out = self._pace.timed_out
        if self._pace.may_step(self.sim.steps * self._time_step_ns, time.monotonic_ns()):
            if self._pace.timed_out and not timed_out:
                self.get_logger().warn(
                    f'{PACE_TIMED_OUT_LOG} for {self.config.lockstep_timeout} s (wall): '
                    'running on without one until one comes', throttle_duration_sec=5.0)
            return True
        return False

    def _on_wall_timer(self) -> None:
        if self._lockstep.paused:
            return
        sim_ns = self.sim.steps * self._time_step_ns  # [ns]
        skipped = self._wall.skipped_ns
        quiet, published = self._wall.due(sim_ns, time.time_ns())
        if quiet:
            self._step_physics(quiet * self.config.steps_per_period)
            self._periods += quiet
        for _ in range(published):
            self._advance()
        if self._wall.skipped_ns > skipped:
            self.get_logger().warn(
                f'the sim fell more than {MAX_LAG_NS * 1e-9} s behind the system clock: '
                f'skipped {(self._wall.skipped_ns - skipped) * 1e-9:.3f} s (the machine is '
                'too busy to run it at real time)', throttle_duration_sec=5.0)

    def _on_fast_timer(self) -> None:
        deadline = time.monotonic() + FAST_BATCH_WALL_TIME
        while time.monotonic() < deadline:
            if self._lockstep.paused or not self._may_step():
                # Waiting: no zero-period timer spinning meanwhile (it took a core from the
                # controller it waits for); a command, a resume or _wake_fast_timer restarts it.
                self._fast_timer.cancel()
                return
            self._advance()

    def _wake_fast_timer(self) -> None:
        if (self._fast_timer.is_canceled() and not self._lockstep.paused
                and self._may_step()):
            self._fast_timer.reset()

    def _on_lockstep_timer(self) -> None:
        tick = self._lockstep.tick(time.monotonic_ns())
        if tick.timed_out:
            self.get_logger().warn(
                f'{LOCKSTEP_TIMED_OUT_LOG} for {self.config.lockstep_timeout} s: advancing '
                'at real time without one until one comes', throttle_duration_sec=5.0)
        for _ in range(tick.periods):
            self._advance()
        if tick.republish:
            self._publish_state()

    def _publish_state(self) -> None:
        now = time.monotonic_ns()  # [ns]
        stamp, lost = self._publish_messages()
        self._lockstep.published(stamp, now)
        if lost and self.config.lockstep and self._lockstep.heard(stamp, now):
            self._advance()

    def _publish_messages(self) -> tuple[int, bool]:
        """Publish the current state; return its stamp [ns] and whether it was lost."""
        messages = self._messages
        truth = state = self.sim.state()
        lost = False
        if self._sensors is not None:
            sample = self._sensors.sample(state)
            lost = sample.lost
            state = dataclasses.replace(
                state, positions=sample.positions, velocities=sample.velocities,
                orientation=sample.orientation, angular_velocity=sample.angular_velocity,
                linear_acceleration=sample.linear_acceleration)
        if self._wall is None:
            sec, nanosec = sim_time(self.sim.steps, self._time_step_ns)
            if self._periods % self.config.clock_every == 0:
                self._clock_pub.publish(messages.clock(sec, nanosec))
        else:
            sec, nanosec = divmod(self._stamp_ns(), 1_000_000_000)
        if not lost:
            self._joint_pub.publish(messages.joint_state(state, sec, nanosec))
        self._camera.after_period(self._periods, truth, sec, nanosec)
        # imu and ground truth are built only when heard (asking: 1.5 us; building and
        # publishing to nobody: 10 us); a subscriber that appears gets the next one anyway.
        if (not lost and self._periods % self.config.imu_every == 0
                and self._imu_pub.get_subscription_count()):
            self._imu_pub.publish(messages.imu(state, sec, nanosec))
        if (self._periods % self.config.ground_truth_every == 0
                and self._odom_pub.get_subscription_count()):
            self._odom_pub.publish(messages.odometry(truth, sec, nanosec))
        return sec * 1_000_000_000 + nanosec, lost

    # --- callbacks -------------------------------------------------------------------------

    def _on_command(self, data: bytes) -> None:
        fields = read_logged(self.get_logger(), actuator_command_fields, data,
                             'actuator_command')
        if fields is None:
            return
        computed, swivel_torque, drive_speed = fields  # [ns], [N m], [rad/s]
        if not self._lockstep.accepts(computed):
            return  # it answers a state of the world before the last reset
        if self._stale(computed):
            return
        if self._fast_timer is not None:
            self._wake_fast_timer()
        if self._sensors is None:
            if not self._apply(swivel_torque, drive_speed):
                return
        elif not self._sensors.transport.lost():
            # Lost: the board never hears it and goes on with the command it has.
            self._commands.push(self.sim.steps, self._sensors.transport.command_delay(),
                                (swivel_torque, drive_speed))
        if not self.config.lockstep:
            return
        timed_out = self._lockstep.unanswered
        advance = self._lockstep.heard(computed, time.monotonic_ns())
        if timed_out:
            self.get_logger().info(f'{LOCKSTEP_RESUMED_LOG}: waiting for it every period again')
        if advance:
            self._advance()

    def _apply(self, swivel_torque: float, drive_speed: float) -> bool:
        """Give the physics a command; False: refused (logged)."""
        try:
            self.sim.set_command(swivel_torque, drive_speed)
        except ValueError as error:
            self.get_logger().warn(f'ignoring actuator_command: {error}',
                                   throttle_duration_sec=1.0)
            return False
        return True

    def _stale(self, computed: int) -> bool:
        """
        Tell whether a command stamped ``computed`` [ns] is too old to apply.

        Free running on sim time, older than ``max_command_age`` (``CommandPace``: the sim
        waits for its controller, so only a controller catching up after its timeout sends
        such); on the system clock, older than ``watchdog_timeout``: it answers a state that
        old, and applying it would steer open loop. The sim goes on with the command it has
        (the pace or the watchdog stops it). An unstamped command (stamp 0) counts as fresh.
        """
        if self.config.lockstep or computed == 0:
            return False
        age_ns = self._stamp_ns() - computed  # [ns]
        if self._pace is not None:
            self._pace.heard(computed, time.monotonic_ns())
            if not self._pace.stale(computed, self._stamp_ns()):
                return False
            bound = f'max_command_age {self.config.max_command_age} s'
        else:
            watchdog = self.config.physics.watchdog_timeout
            if watchdog == 0.0 or age_ns <= watchdog * 1e9:
                return False
            bound = f'watchdog_timeout {watchdog} s'
        clock = 'sim' if self._wall is None else 'system clock'
        self.get_logger().warn(
            f'dropping actuator_command computed {age_ns * 1e-9:.3f} s of {clock} time ago '
            f'({bound}): the controller is behind the sim', throttle_duration_sec=5.0)
        return True

    def _on_set_paused(self, request: SetBool.Request, response: SetBool.Response):
        advance = self._lockstep.set_paused(request.data, time.monotonic_ns())
        if self._wall is not None and not request.data:
            self._wall.restart(self.sim.steps * self._time_step_ns, time.time_ns())
        self._resumed()
        response.success = True
        response.message = 'paused' if request.data else 'running'
        if advance:
            self._advance()
        return response

    def _resumed(self) -> None:
        """Free running: after a pause the wait for the controller counts afresh."""
        if self._pace is not None and not self._lockstep.paused:
            self._pace.restart(time.monotonic_ns())
            if self._fast_timer is not None:
                self._wake_fast_timer()

    @staticmethod
    def _steps_refusal(steps: int) -> str | None:
        """Why a ~/step or ~/run request of ``steps`` is refused; None: it is not."""
        if 1 <= steps <= MAX_STEPS_PER_CALL:
            return None
        return f'steps must be in [1, {MAX_STEPS_PER_CALL}], got {steps}'

    def _on_step(self, request: StepSimulation.Request, response: StepSimulation.Response):
        refusal = self._steps_refusal(request.steps)
        if refusal is None and not (self._lockstep.paused or self.config.lockstep):
            refusal = 'the sim is free running: pause it (~/set_paused) or use lockstep'
        if refusal is not None:
            response.success = False
            response.message = refusal
        else:
            remaining = request.steps
            per_period = self.config.steps_per_period
            while remaining > 0:
                chunk = min(remaining, per_period - self.sim.steps % per_period)
                self._step_physics(chunk)
                remaining -= chunk
                if self.sim.steps % per_period == 0:
                    self._periods += 1
                    self._publish_state()
            self._lockstep.stepped(self._stamp_ns())
            response.success = True
            response.message = f'stepped {request.steps} steps'
        response.sim_time = self._stamp()
        return response

    def _on_run(self, request: StepSimulation.Request, response: StepSimulation.Response):
        refusal = self._steps_refusal(request.steps)
        if refusal is None and self._wall is not None:
            refusal = ('~/run counts sim time, and with clock_source wall the sim runs at real '
                       'time: use ~/set_paused')
        if refusal is not None:
            response.success = False
            response.message = refusal
            response.sim_time = self._stamp()
            return response
        periods = -(-request.steps // self.config.steps_per_period)  # rounded up
        advance = self._lockstep.run_for(periods, time.monotonic_ns())
        self._resumed()
        pause_at_ns = self._lockstep.pause_at_ns  # [ns]
        response.success = True
        response.message = (f'running {periods} control periods, then pausing at '
                            f'{pause_at_ns * 1e-9:.3f} s')
        response.sim_time = sim_time_msg(pause_at_ns // self._time_step_ns, self._time_step_ns)
        if advance:
            self._advance()
        return response

    def _on_reset(self, request: ResetSimulation.Request, response: ResetSimulation.Response):
        try:
            self.sim.reset(request.x, request.y, request.yaw, request.remove_obstacles)
        except ValueError as error:
            response.success = False
            response.message = f'reset refused: {error}'
            return response
        self._commands.clear()
        response.success = True
        response.message = f'robot at ({request.x}, {request.y}, {request.yaw})'
        # The reset takes the rest of this control period, with the zero command it set: the
        # state after it has a stamp of its own, so an answer to a state before it cannot
        # pass for an answer to it. The event goes out first: a controller that hears it
        # starts afresh from that state on (docs/architecture.md).
        self.sim.step(self.config.steps_per_period
                      - self.sim.steps % self.config.steps_per_period)
        self._periods += 1
        if self._sensors is not None:
            self._sensors.reset(self.sim.state())  # a new world: the sensors start afresh
        self._reset_pub.publish(Header(stamp=self._stamp(), frame_id=self.config.world_frame_id))
        now = time.monotonic_ns()  # [ns]
        stamp, lost = self._publish_messages()
        self._lockstep.reset(stamp, now)
        if lost and self.config.lockstep and self._lockstep.heard(stamp, now):
            self._advance()
        return response

    def _on_spawn(self, request: SpawnObstacle.Request, response: SpawnObstacle.Response):
        o = request.obstacle
        try:
            response.name = self.sim.spawn_obstacle(StepSpec(
                o.name, o.height, o.depth, o.width, o.distance, o.yaw, o.friction))
        except ValueError as error:
            response.success = False
            response.message = f'spawn refused: {error}'
            return response
        response.success = True
        response.message = f'spawned {response.name}'
        return response

    def _on_remove(self, request: RemoveObstacle.Request, response: RemoveObstacle.Response):
        try:
            self.sim.remove_obstacle(request.name)
        except ValueError as error:
            response.success = False
            response.message = f'remove refused: {error}'
            return response
        response.success = True
        response.message = f'removed {request.name or "all obstacles"}'
        return response


def main(args=None) -> None:
    sys.exit(run_node(SimNode, 'sim', args))


if __name__ == '__main__':
    main()
