"""
The planner node: climb_step as a service and as an action, one shared climb.

The core's ``ClimbStateMachine`` steps once per controller state, on the inputs of that
moment (``core.sync``), and the command it answers carries that moment's stamp: in a lockstep
sim the controller applies it exactly one cycle later (its ``lockstep_swivel_command``), so a
climb does not depend on how busy the machine is. It runs on the EventsExecutor (a message
in about a quarter of a SingleThreadedExecutor's time), and nothing waits for a climb in a
callback or a task: a request starts the planning, the planning's end starts the climb, the
climb's end answers (the service's callback returns a future of its response, sent once that
completes; an action goal executes only then, to report the result). A coroutine waiting for
the climb would cost CPU all along: the EventsExecutor resumes every waiting task after each
message, and spun one callback at a time (``run_node``) it resumes them again at once, a busy
loop. Planning takes seconds of CPU when a backup is searched: it runs on a worker thread,
which hands its result to the executor as a task (``create_task`` wakes it from any thread; the
EventsExecutor has no guard conditions).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
import math
import sys
import threading
import time
from typing import Callable

from builtin_interfaces.msg import Time as TimeMsg
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.action.server import ServerGoalHandle
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.service import Service
from rclpy.task import Future
from rclpy.time import Time
from sensor_msgs.msg import Imu
from std_msgs.msg import Header
from swivel_car_model import dynamics, kinematics
from swivel_car_model.checks import check_number
from swivel_car_msgs.action import ClimbStep as ClimbStepAction
from swivel_car_msgs.msg import ClimbOutcome, ClimbPlan, SwivelCommand, SwivelControllerState
from swivel_car_msgs.srv import ClimbStep as ClimbStepService
from swivel_car_planner.conversions import (
    controller_state_fields, imu_fields, odom_fields, outcome_to_msg, plan_to_msg, request_from)
from swivel_car_planner.core import (
    capability, ClimbPlan as Plan, ClimbRequest, ClimbStateMachine, Command, ErrorCode, inputs,
    make_plan, PlanError, PlannerConfig, validate_request)
from swivel_car_planner.core.sync import InputSync, Tick
from swivel_car_ros.lockstep import ChainEntry, Entry
from swivel_car_ros.ros_params import (
    declare_description, moment_seconds, run_node, stamp_to_seconds)
from swivel_car_ros.serialized import read_logged

_CONTROLLER_STATE = inputs.CONTROLLER_STATE
_INPUTS = inputs.INPUTS


@dataclass
class _ActiveClimb:
    """
    The one running climb, and who waits for it.

    Its ``entry`` engages once the controller has heard its first command: from then on the
    controller (in the lockstep chain) waits for each of its commands, so its ticks come one
    control period apart.
    """

    new_machine: Callable[[], ClimbStateMachine]
    plan: Plan
    answer: Callable[[_Result], None]  # takes the result once the climb has ended
    goal_handle: ServerGoalHandle | None = None
    machine: ClimbStateMachine = field(init=False)
    entry: ChainEntry = field(default_factory=ChainEntry)  # its way into the chain
    first_command: Command | None = None  # stands for each tick until the entry engages

    def __post_init__(self) -> None:
        self.machine = self.new_machine()


@dataclass
class _Result:
    """The fields shared by the service response and the action result."""

    success: bool
    error_code: int
    message: str
    plan: ClimbPlan
    outcome: ClimbOutcome

    def fill(self, message):
        for name in ('success', 'error_code', 'message', 'plan', 'outcome'):
            setattr(message, name, getattr(self, name))
        return message


class _AnsweredLater(Service):
    """
    A service whose callback returns a Future of its response, sent once that completes.

    Both executors send what a service callback returns through ``send_response``.
    """

    def send_response(self, response: Future, header) -> None:
        response.add_done_callback(
            lambda done: Service.send_response(self, done.result(), header))


class _PlanWorker:
    """
    Plans on worker threads; each plan's future completes on the node's executor.

    A plan still running when the node is destroyed is dropped (its thread is a daemon).
    """

    def __init__(self, node: Node) -> None:
        self._node = node
        self._lock = threading.Lock()
        self._closed = False

    def plan(self, robot, config: PlannerConfig, request: ClimbRequest,
             whole_car_limit: float) -> Future:
        """Start ``make_plan`` on a thread; its future gets the plan, or the PlanError raised."""
        future = Future()
        executor = self._node.executor

        def work() -> None:
            try:
                complete, value = future.set_result, make_plan(
                    robot, config, request, whole_car_limit)
            except Exception as raised:  # raised again by the future's result()
                complete, value = future.set_exception, raised
            with self._lock:
                if not self._closed:
                    executor.create_task(complete, value)

        threading.Thread(target=work, name='climb_step planning', daemon=True).start()
        return future

    def close(self) -> None:
        with self._lock:
            self._closed = True


class PlannerNode(Node):
    """Serves ``climb_step`` (service and action); publishes ``swivel_command``."""

    def __init__(self, **kwargs) -> None:
        super().__init__('planner', **kwargs)
        # The climb's settings apply from the next climb on; the rest is read-only. All
        # dynamically typed, so that an integer where a number is due passes; the configs
        # check the types.
        self.config = PlannerConfig(**{
            item.name: self.declare_parameter(
                item.name, item.default, ParameterDescriptor(
                    description=item.metadata['description'], dynamic_typing=True)).value
            for item in fields(PlannerConfig)})
        self.add_on_set_parameters_callback(self._check_config)
        self.add_post_set_parameters_callback(self._apply_config)
        self.description = declare_description(self)
        self.robot = self.description.model_params()
        self.whole_car_limit = self._load_capability(self.declare_parameter(
            'capability_file', capability.INSTALLED, ParameterDescriptor(
                description="the measured whole-car capability table (YAML); 'installed': "
                            "the package's config/capability.yaml; 'none': no table, only "
                            "the model's limits", read_only=True)).value)
        self._ready_timeout = self._positive_parameter(
            'ready_timeout', 1.0, 'inputs older than this (in sim and wall time) mean not '
                                  'ready; a climb whose inputs stop for this long aborts [s]')

        self._climb: _ActiveClimb | None = None
        self._planning = False  # a climb's plan is being made (the climb slot is taken)
        self._resets = 0  # sim/reset_events heard
        self._plans = _PlanWorker(self)
        # topic -> (sim time [s], steady clock [s]) of its last message
        self._received: dict[str, tuple[float, float]] = {}
        self._clock_last = -math.inf  # [s] the node clock at the last input heard
        self._clock_moved_wall = -math.inf  # [s] steady clock when an input last saw it move
        self._sync = InputSync(_INPUTS, _CONTROLLER_STATE)
        self._refusals = inputs.RefusalLog(5.0)  # [s] as read_logged's lines
        self._last_tick = 0.0  # [s] node clock when the running climb last had a tick
        self._last_tick_wall = 0.0  # [s] steady clock then
        self._last_tick_stamp = -math.inf  # [s] the stamp of the climb's last engaged tick
        self._quiet_checks = 0  # input checks in a row that saw no tick
        self._quiet_wall_checks = 0

        # Serialized: the planner reads a few fields of each (conversions.odom_fields).
        self.create_subscription(Odometry, 'odom', self._on_odom, 10, raw=True)
        self.create_subscription(Imu, 'imu', self._on_imu, 10, raw=True)
        self.create_subscription(SwivelControllerState, _CONTROLLER_STATE,
                                 self._on_controller_state, 10, raw=True)
        self.create_subscription(Header, 'sim/reset_event', self._on_sim_reset, 10)
        self._command_pub = self.create_publisher(SwivelCommand, 'swivel_command', 10)
        self.create_service(ClimbStepService, 'climb_step',
                            self._on_service).__class__ = _AnsweredLater
        self._action = ActionServer(
            self, ClimbStepAction, 'climb_step', execute_callback=self._on_execute,
            goal_callback=self._on_goal, cancel_callback=self._on_cancel,
            handle_accepted_callback=self._on_accepted)
        self._goal_results: dict[bytes, _Result] = {}  # goal id -> the result of its climb
        self.create_timer(self._ready_timeout / 4.0, self._check_inputs_alive)
        # A dead sim stops /clock, and with it every sim-time timer: this one is not stopped.
        self.create_timer(self._ready_timeout / 4.0, self._check_sim_alive,
                          clock=Clock(clock_type=ClockType.STEADY_TIME))
        # The model's swivel drift is integrated once per robot (0.3 s of CPU); done now, the
        # first climb's planning does not take that much longer.
        dynamics.swivel_pose_drift(self.robot, 0.0, self.robot.max_swivel_angle)
        self.get_logger().info(
            f'planner ready: model max scalable step {self._max_step():.3f} m, torque limit '
            f'{self.robot.swivel_torque_limit:.1f} N m')

    def _positive_parameter(self, name: str, default: float, description: str) -> float:
        value = self.declare_parameter(name, default, ParameterDescriptor(
            description=description, dynamic_typing=True, read_only=True)).value
        return check_number(f'parameter {name}', value, above=0.0)

    def _changed_config(self, parameters: list) -> PlannerConfig:
        """Return the climb settings with ``parameters`` set; ValueError names a bad one."""
        names = {item.name for item in fields(PlannerConfig)}
        return replace(self.config, **{p.name: p.value for p in parameters if p.name in names})

    def _check_config(self, parameters: list) -> SetParametersResult:
        try:
            self._changed_config(parameters)
        except ValueError as error:
            return SetParametersResult(successful=False, reason=str(error))
        return SetParametersResult(successful=True)

    def _apply_config(self, parameters: list) -> None:
        config = self._changed_config(parameters)
        if config != self.config:
            self.config = config
            self.get_logger().info('climb settings changed: they apply from the next climb')

    def _load_capability(self, value: str) -> float:
        """
        Return the highest step the whole car climbs reliably [m].

        From the table ``value`` names (``capability.table_for``).

        Raises
        ------
        ValueError
            The file cannot be read as a table.

        """
        table, path = capability.table_for(value)
        if table is None:
            self.get_logger().warning('no capability table: steps are refused only by the '
                                      "model's limits, the rear axle may not follow")
            return math.inf
        if not table.matches(self.description):
            self.get_logger().warning(
                f'the capability table {path} was measured on another robot description; '
                'its limit may not hold for this one (regenerate it: python -m '
                'swivel_car_bringup.climb_benchmark --write-capability)')
        self.get_logger().info(f'whole-car limit {table.limit:.3f} m (success >= '
                               f'{table.reliable:.0%} in {path})')
        return table.limit

    def _max_step(self) -> float:
        return kinematics.max_scalable_step(self.robot)[0]

    # --- inputs ---------------------------------------------------------------------------

    def _now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _on_odom(self, data: bytes) -> None:
        self._take(inputs.ODOM, data, odom_fields, inputs.odom_values)

    def _on_imu(self, data: bytes) -> None:
        self._take(inputs.IMU, data, imu_fields, inputs.imu_values)

    def _on_controller_state(self, data: bytes) -> None:
        def values(set_point, swivel, swivel_rate, torque, command_stamp):
            return inputs.controller_state_values(
                set_point, torque, moment_seconds(command_stamp), swivel, swivel_rate)

        self._take(_CONTROLLER_STATE, data, controller_state_fields, values)

    def _take(self, topic: str, data: bytes, read: Callable, values: Callable) -> None:
        """Read a serialized input and add its values, while a climb runs; refuse a bad one."""
        if not self._heard(topic):
            return
        fields = read_logged(self.get_logger(), read, data, topic)
        if fields is None:
            return
        stamp, *raw = fields
        try:
            value = values(*raw)
        except ValueError as error:
            line = self._refusals.line(topic, str(error), time.monotonic())
            if line is not None:
                self.get_logger().error(line)
            return
        self._add(topic, stamp, value)

    def _heard(self, topic: str) -> bool:
        """
        Note a message on ``topic``; tell whether its values are wanted: while a climb runs.

        A climb starts from the inputs heard after its planning (``_planned``), so none is
        kept before.
        """
        now, wall = self._now(), time.monotonic()
        self._received[topic] = (now, wall)
        if now != self._clock_last:
            self._clock_last, self._clock_moved_wall = now, wall
        return self._climb is not None

    def _clock_stands(self) -> bool:
        """Tell whether the inputs have seen the node clock stand still for ready_timeout."""
        return time.monotonic() - self._clock_moved_wall > self._ready_timeout

    def _add(self, topic: str, stamp: TimeMsg, value: tuple) -> None:
        for tick in self._sync.add(topic, stamp_to_seconds(stamp), value):
            self._on_tick(tick)

    def _missing_inputs(self, wall_too: bool = False) -> list[str]:
        """
        List the inputs not heard within ``ready_timeout`` of sim time (all, before /clock).

        ``wall_too``: only those not heard within ``ready_timeout`` of wall time either (for a
        request). Out of a climb the planner is outside the lockstep chain and the sim races
        ahead of it: a planner not scheduled for a tenth of a second then takes the newest
        /clock first (its subscription keeps only that one) and the inputs of the same moments
        after it, from their queues, which look a second old in sim time though they came
        milliseconds ago (seen on a loaded machine: the clock leapt 1.15 s ahead of them in
        0.13 s of wall time, and a request then was refused on a running stack). An input that
        has stopped is silent on both clocks. A clock that stands still (a sim gone, or one
        restarted but unheard) keeps every input fresh in sim time: then wall time alone tells.
        """
        now, wall = self._now(), time.monotonic()
        timeout = self._ready_timeout
        clock_stands = self._clock_stands()

        def silent(topic: str) -> bool:
            sim, steady = self._received[topic]
            return (now - sim > timeout or clock_stands) and \
                (not wall_too or wall - steady > timeout)

        return [topic for topic in _INPUTS
                if now <= 0.0 or topic not in self._received or silent(topic)]

    # --- the climb ------------------------------------------------------------------------

    def _start(self, request: ClimbRequest, answer: Callable[[_Result], None],
               goal_handle: ServerGoalHandle | None = None) -> None:
        """Validate, plan and (unless plan_only) climb; ``answer`` takes the result at the end."""
        code, message = validate_request(request, self.config)
        if code != ErrorCode.NONE:
            answer(self._failure(code, message))
            return
        if not request.plan_only:
            missing = self._missing_inputs(wall_too=True)
            if missing:
                question = (f'sim time has stood at {self._now():.2f} s: is the sim running, '
                            f'not paused?' if self._clock_stands() else
                            'are the sim, controller and odometry running?')
                answer(self._failure(ErrorCode.NOT_READY,
                                     f'no recent message on {", ".join(missing)}: {question}'))
                return
            if self._busy():
                answer(self._failure(ErrorCode.BUSY,
                                     'a climb is already being planned or running'))
                return
            self._planning = True
        resets = self._resets

        def planned(future: Future) -> None:
            result = self._planned(request, future, resets, answer, goal_handle)
            if result is not None:
                answer(result)

        self._plans.plan(self.robot, self.config, request, self.whole_car_limit
                         ).add_done_callback(planned)

    def _planned(self, request: ClimbRequest, planned: Future, resets: int,
                 answer: Callable[[_Result], None],
                 goal_handle: ServerGoalHandle | None) -> _Result | None:
        """Return the result of a finished planning; None when the climb has started."""
        if not request.plan_only:
            self._planning = False
        try:
            plan = planned.result()
        except PlanError as error:
            return self._failure(error.code, error.message)
        if request.plan_only:
            return _Result(True, int(ErrorCode.NONE), 'plan only: the robot did not move',
                           plan_to_msg(plan), ClimbOutcome())
        if goal_handle is not None and goal_handle.is_cancel_requested:
            return self._failure(ErrorCode.CANCELED, 'canceled while planning: nothing moved')
        if self._resets != resets:
            return self._failure(ErrorCode.NOT_READY, 'the sim was reset while the climb was '
                                 'planned: nothing moved, ask again in the new world')
        climb = _ActiveClimb(
            lambda: ClimbStateMachine(self.robot, self.config, plan, request.step_distance,
                                      request.step_yaw, request.time_allowance),
            plan, answer, goal_handle)
        # The climb starts from the moments after its planning (seconds, when a backup is
        # searched): a tick of the inputs collected before would be that old.
        self._sync.clear()
        self._climb = climb
        self._last_tick = self._now()
        self._last_tick_wall = time.monotonic()
        self._last_tick_stamp = -math.inf
        self._quiet_checks = self._quiet_wall_checks = 0
        self.get_logger().info(
            f'climbing a {request.step_height:.3f} m step {request.step_distance:.2f} m ahead: '
            f'swivel {plan.swivel_angle:.3f} rad, approach heading '
            f'{plan.approach_heading:.3f} rad')
        return None

    def _busy(self) -> bool:
        return self._planning or self._climb is not None

    def _failure(self, code: ErrorCode, message: str) -> _Result:
        self.get_logger().warning(f'climb_step refused ({code.name}): {message}')
        return _Result(False, int(code), message, ClimbPlan(), ClimbOutcome())

    def _on_tick(self, tick: Tick) -> None:
        climb = self._climb
        if climb is None:
            return
        if tick.time < self._last_tick_stamp:
            self._abort(climb, tick.time, ErrorCode.NOT_READY,
                        f'time went back from {self._last_tick_stamp:.2f} s to '
                        f'{tick.time:.2f} s (a restarted sim?): the climb does not go on in '
                        f'another world')
            return
        if math.isfinite(self._last_tick_stamp) \
                and tick.time - self._last_tick_stamp > self._ready_timeout:
            # Engaged, consecutive states are a control period apart: a leap is a bad stamp,
            # a clock that jumped or a planner the controller gave up waiting for, and acting
            # on it would time out or steer on a lie.
            self._abort(climb, self._last_tick_stamp, ErrorCode.NOT_READY,
                        f'the inputs leapt from {self._last_tick_stamp:.2f} s to '
                        f'{tick.time:.2f} s, more than ready_timeout ({self._ready_timeout} '
                        f's): not acted on')
            return
        self._last_tick = self._now()
        self._last_tick_wall = time.monotonic()
        self._quiet_checks = self._quiet_wall_checks = 0
        entry = climb.entry.state(tick.time, inputs.command_heard(tick))
        if entry is Entry.REPEAT:
            self._publish_command(climb.first_command, tick.time)
            return
        if entry is Entry.ENGAGED_LATE:
            # The moment the first command answered is gone: the climb starts afresh from
            # this one, which the controller holds.
            climb.machine = climb.new_machine()
            self.get_logger().info(
                f'the controller heard the first command of {climb.entry.first:.2f} s only at '
                f'{tick.time:.2f} s: the climb starts from there')
        if climb.entry.engaged:
            self._last_tick_stamp = tick.time
        if climb.goal_handle is not None and climb.goal_handle.is_cancel_requested:
            climb.machine.cancel()
        command = climb.machine.update(inputs.observation(tick))
        if entry is Entry.FIRST:
            climb.first_command = command
        self._publish_command(command, tick.time)
        if climb.goal_handle is not None:
            climb.goal_handle.publish_feedback(self._feedback_msg(climb.machine.feedback))
        if climb.machine.outcome is not None:
            self._end(climb, tick.time)

    def _check_inputs_alive(self) -> None:
        """
        End a climb whose inputs stopped (odometry or controller gone).

        The controller's swivel_command deadman has stopped the car by then.
        Only after two checks in a row without a tick: after the executor was held up (a
        loaded machine), this timer runs before the queued inputs and would see a stale tick.
        """
        climb = self._climb
        if climb is None or not climb.entry.engaged:
            return  # the sim is not held back for the planner yet: sim time may race
        self._quiet_checks += 1
        now = self._now()
        if self._quiet_checks < 2 or now - self._last_tick <= self._ready_timeout:
            return
        missing = ', '.join(self._missing_inputs()) or 'none'
        self._abort(climb, now, ErrorCode.NOT_READY,
                    f'no complete input for {now - self._last_tick:.1f} s of sim time at '
                    f'{now:.2f} s; missing: {missing}; {self._sync.describe()}')

    def _check_sim_alive(self) -> None:
        """
        End a climb whose sim died (or was paused) after ``ready_timeout`` of wall time.

        That is, without a tick: sim time stands still then, so the sim-time check never
        fires.
        """
        climb = self._climb
        if climb is None:
            return
        self._quiet_wall_checks += 1
        quiet = time.monotonic() - self._last_tick_wall  # [s] wall
        if self._quiet_wall_checks < 2 or quiet <= self._ready_timeout:
            return
        now = self._now()
        self._abort(climb, now, ErrorCode.NOT_READY,
                    f'no complete input for {quiet:.1f} s of wall time while sim time went '
                    f'from {self._last_tick:.2f} s to {now:.2f} s: is the sim running (not '
                    f'paused)? {self._sync.describe()}')

    def _on_sim_reset(self, msg: Header) -> None:
        """
        End the running climb: the sim was reset, its world is gone (NOT_READY).

        Only the release is sent, stamped with the first state of the new world: the
        controller, reset by the same event, holds the swivel where it measures it then with
        the drive stopped; the usual stop would hold the swivel at the old world's angle.
        """
        self._resets += 1
        climb = self._climb
        if climb is None:
            return
        stamp = stamp_to_seconds(msg.stamp)  # [s]
        climb.machine.abort(ErrorCode.NOT_READY,
                            f'the sim was reset at {stamp:.2f} s: the climb does not go on in '
                            f'the reset world')
        self._end(climb, stamp)

    def _abort(self, climb: _ActiveClimb, stamp: float, code: ErrorCode, message: str) -> None:
        command = climb.machine.abort(code, message)
        if command is not None:
            self._publish_command(command, stamp)
        self._end(climb, stamp)

    def _end(self, climb: _ActiveClimb, stamp: float) -> None:
        """
        End the climb; after a failure the swivel holds where it is and is released.

        The last command holds it; the controller keeps holding it, and cmd_vel steers again.
        """
        self._climb = None
        outcome = climb.machine.outcome
        for command in inputs.end_commands(outcome):
            self._publish_command(command, stamp)
        if outcome.success:
            self.get_logger().info(f'climb ended: {outcome.message}')
        else:
            self.get_logger().warning(f'climb ended ({outcome.error_code.name}): '
                                      f'{outcome.message}')
        climb.answer(_Result(outcome.success, int(outcome.error_code), outcome.message,
                             plan_to_msg(climb.plan), outcome_to_msg(outcome)))

    def _publish_command(self, command: Command, stamp: float) -> None:
        msg = SwivelCommand()
        msg.header.stamp = Time(nanoseconds=round(stamp * 1e9)).to_msg()
        msg.angle = float(command.angle)
        msg.max_rate = float(command.max_rate)
        msg.drive_speed = float(command.drive_speed)
        msg.hold = bool(command.hold)
        msg.free = bool(command.free)
        self._command_pub.publish(msg)

    @staticmethod
    def _feedback_msg(feedback) -> ClimbStepAction.Feedback:
        msg = ClimbStepAction.Feedback()
        msg.phase = int(feedback.phase)
        msg.phase_name = feedback.phase_name
        for name in ('progress', 'pitch', 'roll', 'swivel_angle', 'swivel_torque',
                     'distance_to_edge'):
            setattr(msg, name, float(getattr(feedback, name)))
        return msg

    # --- service and action ---------------------------------------------------------------

    def _on_service(self, request, response) -> Future:
        answered = Future()
        self._start(request_from(request, with_time_allowance=False),
                    lambda result: answered.set_result(result.fill(response)))
        return answered

    def _on_goal(self, goal) -> GoalResponse:
        if self._busy() and not goal.plan_only:
            self.get_logger().warning(
                'climb_step goal rejected: a climb is already being planned or running')
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def _on_cancel(self, goal_handle) -> CancelResponse:
        return CancelResponse.ACCEPT

    def _on_accepted(self, goal_handle: ServerGoalHandle) -> None:
        """Start the goal's climb; the goal executes once it has ended, to report the result."""
        def answer(result: _Result) -> None:
            self._goal_results[bytes(goal_handle.goal_id.uuid)] = result
            goal_handle.execute()

        self._start(request_from(goal_handle.request, with_time_allowance=True), answer,
                    goal_handle)

    def _on_execute(self, goal_handle: ServerGoalHandle) -> ClimbStepAction.Result:
        result = self._goal_results.pop(bytes(goal_handle.goal_id.uuid))
        if result.success:
            goal_handle.succeed()
        elif result.error_code == ErrorCode.CANCELED and goal_handle.is_cancel_requested:
            goal_handle.canceled()
        else:
            goal_handle.abort()
        return result.fill(ClimbStepAction.Result())

    def destroy_node(self) -> None:
        self._plans.close()
        self._action.destroy()
        super().destroy_node()


def main(args=None) -> None:
    sys.exit(run_node(PlannerNode, 'planner', args))


if __name__ == '__main__':
    main()
