"""
The planner node: climb_step as a service and as an action, one shared climb (``ClimbSlot``).

A thin adapter of the core: the ``ClimbStateMachine`` steps once per controller state, on the
inputs of that moment (``core.sync``), and the command it answers carries that moment's stamp:
in a lockstep sim the controller applies it exactly one cycle later, so a climb does not
depend on how busy the machine is. ``InputLiveness`` says when the inputs count as alive.
Nothing waits for a climb in a callback or a task (on the EventsExecutor a waiting coroutine
is resumed after every message): a request starts the planning, on a worker thread (seconds
of CPU when a backup is searched); the planning's end starts the climb; the climb's end
answers (the service's response, an action goal's execution).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import math
import sys
import threading
import time
from typing import Callable

from builtin_interfaces.msg import Time as TimeMsg
from nav_msgs.msg import Odometry
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
from swivel_car_model.description import described
from swivel_car_msgs.action import ClimbStep as ClimbStepAction
from swivel_car_msgs.msg import (
    ClimbOutcome, ClimbPlan, DetectedStep, SwivelCommand, SwivelControllerState)
from swivel_car_msgs.srv import ClimbStep as ClimbStepService
from swivel_car_perception.core.detector import Detection
from swivel_car_planner.conversions import (
    controller_state_fields, imu_fields, odom_fields, outcome_to_msg, plan_to_msg, request_from)
from swivel_car_planner.core import (
    capability, ClimbPlan as Plan, ClimbRequest, ClimbStateMachine, Command, ErrorCode, inputs,
    make_plan, PlanError, PlannerConfig, validate_request)
from swivel_car_planner.core.detected import DetectedSteps
from swivel_car_planner.core.liveness import ClimbSlot, InputLiveness
from swivel_car_planner.core.sync import InputSync, Tick
from swivel_car_ros.lockstep import ChainEntry, Entry
from swivel_car_ros.ros_params import (
    declare_dataclass, declare_description, live_parameters, moment_seconds, run_node,
    stamp_to_seconds)
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
    use_detected_step: bool = False  # follows the detector's edge during the approach
    requested_at: float = -math.inf  # [s] node clock at the request (see _reset_since)
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


def _answer_later(service: Service) -> None:
    """
    Make ``service`` send what its callback returns, a Future of the response, once done.

    rclpy has no deferred service response (rclcpp has had one since Humble). Its pattern, a
    coroutine callback that awaits a Future, needs an executor that awaits the callback:
    ``Executor._take_service`` does (executors.py: ``response = await
    await_or_execute(srv.callback, ...)``), but Jazzy's EventsExecutor, which ``run_node``
    gives, calls it and passes what it returns, the coroutine, to ``send_response``, which
    raises TypeError (events_executor.cpp, ``HandleServiceReady``: ``response =
    callback(request, res_type());`` then ``send_response(response, header);``; rolling awaits
    it since ros2/rclpy#1478, not the rclpy 7.1.6 this stack pins). On the
    SingleThreadedExecutor, which awaits it, the planner's system test takes a third more CPU.
    Both executors look ``send_response`` up on the service for each request: this one, set on
    the instance, waits for the Future first.
    """
    send = service.send_response
    service.send_response = lambda answered, header: answered.add_done_callback(
        lambda done: send(done.result(), header))


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


@dataclass(frozen=True)
class PlannerNodeConfig:
    """
    The planner's settings outside the climb's: its capability table and input timeouts.

    Each field's metadata ``description`` (with its unit) is also its ROS parameter's.

    Raises
    ------
    ValueError
        A timeout is not a finite number > 0; the message names it.

    """

    capability_file: str = described(
        capability.INSTALLED, "the measured whole-car capability table (YAML); 'installed': the "
        "package's config/capability.yaml; 'none': no table, only the model's limits")
    ready_timeout: float = described(
        1.0, 'inputs older than this (in sim and wall time) mean not ready; a climb whose inputs '
        'stop for this long aborts [s]')
    detection_max_age: float = described(
        0.5, 'use_detected_step: the oldest detected_step a climb takes (the detector publishes '
        'one per image) [s]')

    def __post_init__(self) -> None:
        for name in ('ready_timeout', 'detection_max_age'):
            check_number(name, getattr(self, name), above=0.0)


class PlannerNode(Node):
    """Serves ``climb_step`` (service and action); publishes ``swivel_command``."""

    def __init__(self, **kwargs) -> None:
        super().__init__('planner', **kwargs)
        # The climb's settings apply from the next climb on; the rest is read-only.
        self.config = declare_dataclass(self, PlannerConfig)
        live_parameters(self, PlannerConfig.LIVE,
                        lambda changes: replace(self.config, **changes), self._apply_config)
        self.description = declare_description(self)
        self.robot = self.description.model_params()
        node = declare_dataclass(self, PlannerNodeConfig)
        self.whole_car_limit = self._load_capability(node.capability_file)
        self._ready_timeout = node.ready_timeout
        self._detected = DetectedSteps(self.description.wheelbase, node.detection_max_age)
        self._slot: ClimbSlot[_ActiveClimb] = ClimbSlot()
        self._resets = 0  # sim/reset_events heard
        self._reset_stamp = -math.inf  # [s] the newest one's: the first state of its world
        self._plans = _PlanWorker(self)
        self._liveness = InputLiveness(_INPUTS, self._ready_timeout)
        self._sync = InputSync(_INPUTS, _CONTROLLER_STATE)
        self._attitude = inputs.Attitude(self.config.attitude_time_constant)
        self._refusals = inputs.RefusalLog(5.0)  # [s] as read_logged's lines

        # Serialized: the planner reads a few fields of each (conversions.odom_fields).
        self.create_subscription(Odometry, 'odom', self._on_odom, 10, raw=True)
        self.create_subscription(Imu, 'imu', self._on_imu, 10, raw=True)
        self.create_subscription(SwivelControllerState, _CONTROLLER_STATE,
                                 self._on_controller_state, 10, raw=True)
        self.create_subscription(Header, 'sim/reset_event', self._on_sim_reset, 10)
        self.create_subscription(DetectedStep, 'detected_step', self._on_detected_step, 10)
        self._command_pub = self.create_publisher(SwivelCommand, 'swivel_command', 10)
        _answer_later(self.create_service(ClimbStepService, 'climb_step', self._on_service))
        self._action = ActionServer(
            self, ClimbStepAction, 'climb_step', execute_callback=self._on_execute,
            goal_callback=self._on_goal, cancel_callback=self._on_cancel,
            handle_accepted_callback=self._on_accepted)
        self._goal_results: dict[bytes, _Result] = {}  # goal id -> the result of its climb
        # A dead sim stops /clock, and with it every sim-time timer: this one is not stopped.
        self.create_timer(self._ready_timeout / 4.0, self._check_alive,
                          clock=Clock(clock_type=ClockType.STEADY_TIME))
        # The model's swivel drift is integrated once per robot (0.3 s of CPU); done now, the
        # first climb's planning does not take that much longer.
        dynamics.swivel_pose_drift(self.robot, 0.0, self.robot.max_swivel_angle)
        self.get_logger().info(
            f'planner ready: model max scalable step {self._max_step():.3f} m, torque limit '
            f'{self.robot.swivel_torque_limit:.1f} N m')

    def _apply_config(self, config: PlannerConfig) -> None:
        """Take the climb settings ``config`` from the next climb on."""
        self.config = config

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
                'swivel_car_studies.climb_benchmark --write-capability)')
        bound = ('' if table.confidence is None
                 else f'lower {table.confidence:.0%} confidence bound on ')
        self.get_logger().info(f'whole-car limit {table.limit:.3f} m ({bound}success >= '
                               f'{table.reliable:.0%} in {path})')
        return table.limit

    def _max_step(self) -> float:
        return kinematics.max_scalable_step(self.robot)[0]

    # --- inputs ---------------------------------------------------------------------------

    def _now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _on_odom(self, data: bytes) -> None:
        if self._slot.climb is None:  # a climb notes the poses it steers by (_on_tick)
            fields = read_logged(self.get_logger(), odom_fields, data, inputs.ODOM)
            if fields is not None:
                stamp, x, y, orientation, _ = fields
                if all(math.isfinite(v) for v in (x, y, *orientation)):
                    self._detected.pose(stamp_to_seconds(stamp), x, y,
                                        inputs.yaw_of(*orientation))
        self._take(inputs.ODOM, data, odom_fields, inputs.odom_values)

    def _on_detected_step(self, msg: DetectedStep) -> None:
        s = msg.step
        values = (s.height, s.distance, s.yaw, s.width, msg.step_offset, s.depth,
                  msg.height_std, msg.distance_std, msg.yaw_std, msg.width_std)
        if not all(math.isfinite(v) for v in values):
            line = self._refusals.line('detected_step', 'a non-finite field',
                                       time.monotonic())
            if line is not None:
                self.get_logger().error(line)
            return
        self._detected.heard(stamp_to_seconds(msg.header.stamp), Detection(
            bool(msg.found), '', s.height, s.distance, s.yaw, s.width, msg.step_offset,
            s.depth, msg.height_std, msg.distance_std, msg.yaw_std, msg.width_std,
            bool(msg.left_end_seen), bool(msg.right_end_seen)))

    def _on_imu(self, data: bytes) -> None:
        self._take(inputs.IMU, data, imu_fields, self._attitude.update, stamped=True)

    def _on_controller_state(self, data: bytes) -> None:
        def values(set_point, swivel, swivel_rate, torque, command_stamp):
            return inputs.controller_state_values(
                set_point, torque, moment_seconds(command_stamp), swivel, swivel_rate)

        self._take(_CONTROLLER_STATE, data, controller_state_fields, values)

    def _take(self, topic: str, data: bytes, read: Callable, values: Callable,
              stamped: bool = False) -> None:
        """
        Read a serialized input and add its values, while a climb runs; refuse a bad one.

        ``stamped``: ``values`` takes the message's stamp [s] before its fields.
        """
        if not self._heard(topic):
            return
        fields = read_logged(self.get_logger(), read, data, topic)
        if fields is None:
            return
        stamp, *raw = fields
        try:
            value = values(stamp_to_seconds(stamp), *raw) if stamped else values(*raw)
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
        self._liveness.heard(topic, self._now(), time.monotonic())
        return self._slot.climb is not None

    def _add(self, topic: str, stamp: TimeMsg, value: tuple) -> None:
        for tick in self._sync.add(topic, stamp_to_seconds(stamp), value):
            self._on_tick(tick)

    # --- the climb ------------------------------------------------------------------------

    def _start(self, request: ClimbRequest, answer: Callable[[_Result], None],
               goal_handle: ServerGoalHandle | None = None,
               use_detected_step: bool = False) -> None:
        """
        Validate, plan and (unless plan_only) climb; ``answer`` takes the result at the end.

        With ``use_detected_step`` the step is the detector's (its geometry fields ignored).
        """
        if use_detected_step:
            detected, why = self._detected.request(request, self._now(), self.whole_car_limit)
            if detected is None:
                answer(self._failure(ErrorCode.NO_STEP_DETECTED, why))
                return
            request = detected
            self.get_logger().info(
                f'detected step: {request.step_height:.3f} m high, {request.step_distance:.3f} '
                f'm ahead, yaw {request.step_yaw:.3f} rad, {request.step_width:.2f} m wide')
        code, message = validate_request(request, self.config)
        if code != ErrorCode.NONE:
            answer(self._failure(code, message))
            return
        if not request.plan_only:
            not_ready = self._liveness.not_ready(self._now(), time.monotonic())
            if not_ready is not None:
                answer(self._failure(ErrorCode.NOT_READY, not_ready))
                return
            if not self._slot.take():
                answer(self._failure(ErrorCode.BUSY,
                                     'a climb is already being planned or running'))
                return
        resets, requested_at = self._resets, self._now()

        def planned(future: Future) -> None:
            result = self._planned(request, future, (resets, requested_at), answer,
                                   goal_handle, use_detected_step)
            if result is not None:
                answer(result)

        self._plans.plan(self.robot, self.config, request, self.whole_car_limit
                         ).add_done_callback(planned)

    def _planned(self, request: ClimbRequest, planned: Future,
                 requested: tuple[int, float], answer: Callable[[_Result], None],
                 goal_handle: ServerGoalHandle | None,
                 use_detected_step: bool = False) -> _Result | None:
        """
        Return the result of a finished planning; None when the climb has started.

        ``requested``: the sim/reset_events heard and the node clock [s] at the request.
        """
        if not request.plan_only:
            self._slot.planned(None)
        try:
            plan = planned.result()
        except PlanError as error:
            return self._failure(error.code, error.message)
        if request.plan_only:
            return _Result(True, int(ErrorCode.NONE), 'plan only: the robot did not move',
                           plan_to_msg(plan), ClimbOutcome())
        if goal_handle is not None and goal_handle.is_cancel_requested:
            return self._failure(ErrorCode.CANCELED, 'canceled while planning: nothing moved')
        resets, requested_at = requested
        if self._resets != resets and self._reset_since(self._reset_stamp, requested_at):
            return self._failure(ErrorCode.NOT_READY, 'the sim was reset while the climb was '
                                 'planned: nothing moved, ask again in the new world')
        climb = _ActiveClimb(
            lambda: ClimbStateMachine(self.robot, self.config, plan, request.step_distance,
                                      request.step_yaw, request.time_allowance),
            plan, answer, goal_handle, use_detected_step, requested_at)
        # The climb starts from the moments after its planning (seconds, when a backup is
        # searched): a tick of the inputs collected before would be that old.
        self._sync.clear()
        self._attitude = inputs.Attitude(self.config.attitude_time_constant)
        self._slot.planned(climb)
        self._liveness.climb_started(self._now(), time.monotonic())
        self.get_logger().info(
            f'climbing a {request.step_height:.3f} m step {request.step_distance:.2f} m ahead: '
            f'swivel {plan.swivel_angle:.3f} rad, approach heading '
            f'{plan.approach_heading:.3f} rad')
        return None

    @staticmethod
    def _reset_since(reset_stamp: float, requested_at: float) -> bool:
        """
        Tell whether a sim reset heard after a climb's request came after the request.

        ``reset_stamp``: the reset event's (its world's first state) [s]; ``requested_at``:
        the node clock at the request [s]. A reset event can be heard after the request
        although the world was reset before it: the event travels on a topic of its own, and
        a /clock of the new world, heard first, had already dated the request there (a client
        that reset the sim and then asked). That climb goes on.
        """
        return reset_stamp >= requested_at

    def _failure(self, code: ErrorCode, message: str) -> _Result:
        self.get_logger().warning(f'climb_step refused ({code.name}): {message}')
        return _Result(False, int(code), message, ClimbPlan(), ClimbOutcome())

    def _on_tick(self, tick: Tick) -> None:
        climb = self._slot.climb
        if climb is None:
            return
        failure = self._liveness.tick(tick.time, self._now(), time.monotonic())
        if failure is not None:
            self._abort(climb, failure[0], ErrorCode.NOT_READY, failure[1])
            return
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
            self._liveness.engaged(tick.time)
        if climb.goal_handle is not None and climb.goal_handle.is_cancel_requested:
            climb.machine.cancel()
        observation = inputs.observation(tick)
        command = climb.machine.update(observation)
        self._follow_detection(climb.machine, observation, tick.time)
        if entry is Entry.FIRST:
            climb.first_command = command
        self._publish_command(command, tick.time)
        if climb.goal_handle is not None:
            feedback = self._feedback_msg(climb.machine.feedback)
            if climb.use_detected_step:
                feedback.detected_step = self._detected_step_msg(tick.time)
            climb.goal_handle.publish_feedback(feedback)
        if climb.machine.outcome is not None:
            self._end(climb, tick.time)

    def _follow_detection(self, machine: ClimbStateMachine, obs, stamp: float) -> None:
        """Note the climb's pose; in a detected climb's approach, follow new detections."""
        moved = self._detected.follow(machine, obs, stamp, self._slot.climb.use_detected_step)
        if moved is not None:
            self.get_logger().info(f'approach: the detected edge is {moved[0]:+.3f} m and '
                                   f'{moved[1]:+.3f} rad from the planned one: following it')

    def _detected_step_msg(self, stamp: float) -> DetectedStep:
        """Return the latest fresh detection relative to base_link now (found false: none)."""
        d, _ = self._detected.fresh(stamp)
        msg = DetectedStep(found=d is not None)
        msg.header.stamp = Time(nanoseconds=round(stamp * 1e9)).to_msg()
        msg.header.frame_id = 'base_link'
        if d is not None:
            msg.step.height, msg.step.distance, msg.step.yaw = d.height, d.distance, d.yaw
            msg.step.width, msg.step.depth, msg.step_offset = d.width, d.depth_seen, d.offset
            msg.height_std, msg.distance_std = d.height_std, d.distance_std
            msg.yaw_std, msg.width_std = d.yaw_std, d.width_std
            msg.left_end_seen, msg.right_end_seen = d.left_end_seen, d.right_end_seen
        return msg

    def _check_alive(self) -> None:
        """End a climb whose inputs stopped (``InputLiveness.check``): the deadman stopped it."""
        climb = self._slot.climb
        if climb is not None:
            failure = self._liveness.check(self._now(), time.monotonic(), climb.entry.engaged,
                                           self._sync.describe)
            if failure is not None:
                self._abort(climb, failure[0], ErrorCode.NOT_READY, failure[1])

    def _on_sim_reset(self, msg: Header) -> None:
        """
        End the running climb: the sim was reset, its world is gone (NOT_READY).

        Only the release is sent, stamped with the first state of the new world: the
        controller, reset by the same event, holds the swivel where it measures it then with
        the drive stopped; the usual stop would hold the swivel at the old world's angle.
        """
        stamp = stamp_to_seconds(msg.stamp)  # [s]
        self._resets += 1
        self._reset_stamp = stamp
        climb = self._slot.climb
        if climb is None or not self._reset_since(stamp, climb.requested_at):
            return
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
        self._slot.end()
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
                    lambda result: answered.set_result(result.fill(response)),
                    use_detected_step=request.use_detected_step)
        return answered

    def _on_goal(self, goal) -> GoalResponse:
        if self._slot.busy and not goal.plan_only:
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
                    goal_handle, goal_handle.request.use_detected_step)

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
