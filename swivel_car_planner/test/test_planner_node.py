"""
Node tests: the real PlannerNode in-process with real rclpy, fed by a kinematic car.

The test plays the robot: it publishes /clock, imu, odom and the controller state (with the
swivel) of ``KinematicCar`` (the model's planar kinematics) and applies the planner's
swivel_command to it, so the service and action run whole climbs without the sim.
"""

from dataclasses import fields
import math
import os
from pathlib import Path
import threading
import time

from action_msgs.msg import GoalStatus
from builtin_interfaces.msg import Time as TimeMsg
from kinematic_car import DEFAULT_SWIVEL_RATE, DT, KinematicCar
from nav_msgs.msg import Odometry
import pytest
import rclpy
from rclpy.action import ActionClient
from rclpy.experimental import EventsExecutor
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu
from std_msgs.msg import Header
from swivel_car_model import description
from swivel_car_msgs.action import ClimbStep as ClimbStepAction
from swivel_car_msgs.msg import SwivelCommand, SwivelControllerState
from swivel_car_msgs.srv import ClimbStep as ClimbStepService
from swivel_car_planner import planner_node
from swivel_car_planner.core import Command, ErrorCode, Phase, PlannerConfig
from swivel_car_planner.planner_node import PlannerNode
from swivel_car_testing import next_domain_id, spin_until
import yaml

SUCCESSFUL_CLIMB = {'step_height': 0.04, 'step_distance': 1.2, 'step_yaw': 0.0}


def test_error_codes_and_phases_match_the_interfaces():
    response = ClimbStepService.Response
    for code in ErrorCode:
        assert getattr(response, f'ERROR_{code.name}') == code.value
    for phase in Phase:
        assert getattr(ClimbStepAction.Feedback, f'PHASE_{phase.name}') == phase.value


class Rig:
    """Planner on its own executor in a thread; the test's robot and clients."""

    def __init__(self):
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=next_domain_id())
        self.planner = PlannerNode_with_sim_time(self.context)
        # The executor run_node gives it.
        self.planner_executor = EventsExecutor(context=self.context)
        self.planner_executor.add_node(self.planner)
        # Stopped before the executor is shut down, which waits for a spin still running.
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._spin_planner, daemon=True)
        self.thread.start()
        self.node = rclpy.create_node('robot', context=self.context)
        self.executor = EventsExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.car = KinematicCar()
        # The step the tests' climbs name, so the car pitches with its front axle on top.
        self.car.place_step(SUCCESSFUL_CLIMB['step_height'], SUCCESSFUL_CLIMB['step_distance'],
                            SUCCESSFUL_CLIMB['step_yaw'])
        self.command = None
        self.received: list[SwivelCommand] = []
        self.heard = TimeMsg()  # the stamp of the last command, as the controller reports it
        self._last_imu = None  # (time [s], pitch [rad]) of the last imu published
        self.node.create_subscription(SwivelCommand, 'swivel_command', self._on_command, 10)
        self.clock = self.node.create_publisher(Clock, '/clock', 10)
        self.imu = self.node.create_publisher(Imu, 'imu', 10)
        self.odom = self.node.create_publisher(Odometry, 'odom', 10)
        self.state = self.node.create_publisher(
            SwivelControllerState, 'controller/controller_state', 10)
        self.service = self.node.create_client(ClimbStepService, 'climb_step')
        self.action = ActionClient(self.node, ClimbStepAction, 'climb_step')
        spin_until(self.executor, self.service.service_is_ready, 10.0, 'the service')
        spin_until(self.executor, self.action.server_is_ready, 10.0, 'the action server')

    def _spin_planner(self):
        while not self._stop.is_set():
            self.planner_executor.spin_once(timeout_sec=0.05)

    def _on_command(self, msg):
        self.received.append(msg)
        self.heard = msg.header.stamp
        # Only the answer to the state just published: a late answer to an earlier one
        # would put the car out of step with the planner.
        if rclpy.time.Time.from_msg(msg.header.stamp).nanoseconds == self.car.cycles * 10**7:
            self.command = Command(msg.angle, msg.max_rate, msg.drive_speed, msg.hold)

    def publish_state(self, inputs=('imu', 'odom', 'controller'),
                      heard=None):
        """
        Publish one control cycle of the robot: clock, then the requested inputs.

        ``heard``: the command stamp the controller state reports (default: the last command's).
        """
        car = self.car
        stamp = rclpy.time.Time(nanoseconds=car.cycles * 10_000_000).to_msg()
        self.clock.publish(Clock(clock=stamp))
        obs = car.observe()
        if 'imu' in inputs:
            msg = Imu()
            msg.header.stamp = stamp
            # Yaw then pitch: q = q_z(yaw) * q_y(pitch).
            cy, sy = math.cos(obs.imu_yaw / 2.0), math.sin(obs.imu_yaw / 2.0)
            cp, sp = math.cos(obs.pitch / 2.0), math.sin(obs.pitch / 2.0)
            msg.orientation.x, msg.orientation.y = -sy * sp, cy * sp
            msg.orientation.z, msg.orientation.w = sy * cp, cy * cp
            # The gyro as the pitch moves since the last imu (the car turns about z only by
            # its heading, which the planner takes from the orientation).
            last_time, last_pitch = self._last_imu or (car.time, obs.pitch)
            if car.time > last_time:
                msg.angular_velocity.y = (obs.pitch - last_pitch) / (car.time - last_time)
            self._last_imu = (car.time, obs.pitch)
            self.imu.publish(msg)
        if 'odom' in inputs:
            msg = Odometry()
            msg.header.stamp = stamp
            msg.pose.pose.position.x = obs.x
            msg.pose.pose.position.y = obs.y
            msg.pose.pose.orientation.z = math.sin(obs.yaw / 2.0)
            msg.pose.pose.orientation.w = math.cos(obs.yaw / 2.0)
            self.odom.publish(msg)
        if 'controller' in inputs:
            msg = SwivelControllerState(set_point=car.set_point, measured=car.swivel,
                                        measured_rate=car.rate, torque=obs.torque,
                                        source='hold',
                                        swivel_command_stamp=self.heard if heard is None
                                        else heard)
            msg.header.stamp = stamp
            self.state.publish(msg)

    def drive(self, future, seconds=120.0):
        """
        Close the loop until ``future`` is done: the car follows the planner's commands.

        Lockstep by hand: each cycle waits for the planner's command of that cycle (stamped
        with its state). Until a climb is registered there is none (a short wait, then the
        car keeps the last one); from its first command on the planner answers every state,
        so the wait is only a guard and a loaded machine cannot put the car out of step.
        """
        last = Command(0.0, 0.0, 0.0, False)
        answering = False
        while not future.done() and self.car.time < seconds:
            self.publish_state()
            deadline = time.monotonic() + (10.0 if answering else 0.5)
            while self.command is None and not future.done() and time.monotonic() < deadline:
                self.executor.spin_once(timeout_sec=0.005)
            if self.command is not None:
                answering = True
                # A release leaves the swivel where it was and stops, as the controller does.
                last = self.command if self.command.hold else Command(last.angle, 0.0, 0.0, False)
                self.command = None
            self.car.apply(last)
        spin_until(self.executor, future.done, 10.0, 'the result')
        return future.result()

    def warm_up(self, cycles=30, inputs=('imu', 'odom', 'controller')):
        for _ in range(cycles):
            self.publish_state(inputs)
            self.car.cycles += 1
            self.executor.spin_once(timeout_sec=0.005)

    def call(self, **fields):
        return self.service.call_async(ClimbStepService.Request(**fields))

    def close(self):
        self._stop.set()
        self.thread.join(5.0)
        self.action.destroy()
        self.planner_executor.shutdown()
        self.planner.destroy_node()
        self.node.destroy_node()
        rclpy.shutdown(context=self.context)


def PlannerNode_with_sim_time(context):  # noqa: N802
    return PlannerNode(context=context,
                       parameter_overrides=[Parameter('use_sim_time', value=True)])


@pytest.fixture
def rig():
    rig = Rig()
    yield rig
    rig.close()


def result_of(rig, future):
    spin_until(rig.executor, future.done, 10.0, 'the response')
    return future.result()


def test_malformed_request_is_invalid_and_nothing_moves(rig):
    rig.warm_up()
    response = result_of(rig, rig.call(step_height=math.nan, step_distance=1.0))
    assert not response.success
    assert response.error_code == ClimbStepService.Response.ERROR_INVALID_REQUEST
    assert 'step_height' in response.message
    assert rig.command is None


def test_request_before_the_robot_is_up_is_not_ready(rig):
    response = result_of(rig, rig.call(**SUCCESSFUL_CLIMB))
    assert response.error_code == ClimbStepService.Response.ERROR_NOT_READY
    rig.warm_up(inputs=('imu', 'controller'))  # no odometry
    response = result_of(rig, rig.call(**SUCCESSFUL_CLIMB))
    assert response.error_code == ClimbStepService.Response.ERROR_NOT_READY
    assert 'odom' in response.message
    assert rig.command is None


def test_a_clock_ahead_of_the_queued_inputs_is_ready_a_silent_input_is_not(rig):
    """
    Check an input counts as gone only once silent for ready_timeout of sim and of wall time.

    Out of a climb the sim races ahead of the planner: one not scheduled for a moment takes
    the newest /clock before the inputs queued behind it, which then look old in sim time
    though they came milliseconds ago. A stack whose odometry stopped is still refused.
    """
    rig.warm_up()
    rig.car.cycles += 200  # [10 ms] the sim ran 2 s ahead, the inputs of it not yet taken
    rig.publish_state(inputs=())  # the /clock alone
    spin_until(rig.executor, lambda: rig.planner.get_clock().now().nanoseconds
               >= rig.car.cycles * 10**7, 10.0, 'the planner to take the clock')
    response = result_of(rig, rig.call(step_height=0.5, step_distance=1.0))
    assert response.error_code == ErrorCode.UNREACHABLE_HEIGHT, response.message
    # The odometry stops; the rest goes on for more than ready_timeout (1 s) of both clocks.
    start = time.monotonic()
    while time.monotonic() < start + 1.2:
        rig.warm_up(cycles=1, inputs=('imu', 'controller'))
    response = result_of(rig, rig.call(step_height=0.5, step_distance=1.0))
    assert response.error_code == ErrorCode.NOT_READY
    assert response.message.startswith('no recent message on odom: '), response.message
    assert rig.command is None


def test_a_clock_standing_still_keeps_no_silent_input_fresh(rig):
    """
    Check a silent input counts as gone on wall time alone while the clock stands still.

    A planner that does not hear a restarted sim (see tests/test_stack.py) has its clock
    standing at the old sim's last moment, where the old sim's last imu looks fresh in sim
    time: a climb would be accepted and aborted a second later.
    """
    rig.warm_up()
    start = time.monotonic()
    while time.monotonic() < start + 1.2:  # [s] more than ready_timeout
        rig.publish_state(inputs=('odom', 'controller'))  # the same moment: /clock stands
        rig.executor.spin_once(timeout_sec=0.005)
    response = result_of(rig, rig.call(step_height=0.5, step_distance=1.0))
    assert response.error_code == ErrorCode.NOT_READY
    assert response.message.startswith('no recent message on imu: sim time has stood at '), \
        response.message
    assert rig.command is None


def test_plan_only_returns_the_plan_without_moving(rig):
    response = result_of(rig, rig.call(**SUCCESSFUL_CLIMB, plan_only=True))
    assert response.success, response.message
    assert response.plan.swivel_angle > 0.0
    assert response.plan.tip_over_margin > 0.0
    assert response.plan.duration > 0.0
    assert rig.command is None


def test_unreachable_step_is_refused_without_motion(rig):
    rig.warm_up()
    response = result_of(rig, rig.call(step_height=0.5, step_distance=1.0))
    assert response.error_code == ClimbStepService.Response.ERROR_UNREACHABLE_HEIGHT
    assert rig.command is None


def test_service_climbs_and_a_second_request_meanwhile_is_busy(rig):
    rig.warm_up()
    climb = rig.call(**SUCCESSFUL_CLIMB)
    second = []

    def call_again_once_moving():
        if not second and rig.car.time > 1.0:
            second.append(rig.call(**SUCCESSFUL_CLIMB))

    original_apply = rig.car.apply

    def apply(command):
        call_again_once_moving()
        original_apply(command)

    rig.car.apply = apply
    response = rig.drive(climb)
    assert response.success, response.message
    assert response.outcome.distance_travelled > 1.0
    busy = result_of(rig, second[0])
    assert busy.error_code == ClimbStepService.Response.ERROR_BUSY


def send_goal(rig, feedback, **fields):
    goal = ClimbStepAction.Goal(**fields)
    future = rig.action.send_goal_async(goal, feedback_callback=lambda m: feedback.append(
        m.feedback))
    spin_until(rig.executor, future.done, 10.0, 'the goal response')
    return future.result()


def test_action_reports_feedback_and_rejects_a_second_goal(rig):
    rig.warm_up()
    feedback = []
    handle = send_goal(rig, feedback, **SUCCESSFUL_CLIMB)
    assert handle.accepted
    result_future = handle.get_result_async()
    # Drive a second into the climb, then try a second goal: rejected.
    rig.drive(_Deadline(rig, 1.0))
    other = send_goal(rig, [], **SUCCESSFUL_CLIMB)
    assert not other.accepted
    wrapped = rig.drive(result_future)
    assert wrapped.result.success, wrapped.result.message
    phases = [f.phase for f in feedback]
    assert phases[0] == Phase.APPROACH and Phase.CLIMB_REST in phases
    assert phases == sorted(phases)
    assert feedback[-1].progress == pytest.approx(1.0)


def test_action_cancel_stops_the_drive_and_holds_the_swivel(rig):
    rig.warm_up()
    handle = send_goal(rig, [], **SUCCESSFUL_CLIMB)
    result_future = handle.get_result_async()
    rig.drive(_Deadline(rig, 2.0))
    cancel = handle.cancel_goal_async()
    wrapped = rig.drive(result_future)
    assert cancel.done()
    assert wrapped.status == GoalStatus.STATUS_CANCELED
    assert wrapped.result.error_code == ErrorCode.CANCELED
    # Stopped with the swivel held where it was, then released: the controller holds it.
    spin_until(rig.executor, lambda: not rig.received[-1].hold, 10.0, 'the release')
    held, released = rig.received[-2:]
    assert held.drive_speed == 0.0 and held.hold
    # Held where the planner last saw it: the car may have moved one more period since,
    # under the command before the cancel landed.
    assert held.angle == pytest.approx(rig.car.swivel, abs=DEFAULT_SWIVEL_RATE * DT + 1e-6)
    assert not released.hold


def test_each_command_answers_the_moment_of_its_inputs(rig):
    rig.warm_up()
    future = rig.call(**SUCCESSFUL_CLIMB)
    rig.drive(_Deadline(rig, 0.5))
    stamps = [m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in rig.received]
    # One command per published state, stamped with that state's time, in order.
    assert len(stamps) > 20
    assert all(b == pytest.approx(a + 0.01) for a, b in zip(stamps, stamps[1:]))
    assert stamps[-1] == pytest.approx(rig.car.time - 0.01)
    rig.drive(future)


def test_inputs_stopping_mid_climb_abort_it(rig):
    rig.warm_up()
    future = rig.call(**SUCCESSFUL_CLIMB)
    rig.drive(_Deadline(rig, 1.0))
    # The odometry dies: the planner hears no complete moment for ready_timeout (1 s).
    while not future.done() and rig.car.time < 10.0:
        rig.publish_state(inputs=('imu', 'controller'))
        rig.car.cycles += 1
        rig.executor.spin_once(timeout_sec=0.005)
    response = result_of(rig, future)
    assert response.error_code == ErrorCode.NOT_READY
    assert 'odom' in response.message
    assert 0.9 <= response.outcome.duration <= 1.05  # to the last complete moment
    spin_until(rig.executor, lambda: not rig.received[-1].hold, 10.0, 'the release')


def test_a_dead_sim_ends_the_climb_within_ready_timeout_of_wall_time(rig):
    rig.warm_up()
    future = rig.call(**SUCCESSFUL_CLIMB)
    rig.drive(_Deadline(rig, 1.0))
    # Nothing more: no /clock, no inputs. Sim time stands still at 1.3 s.
    start = time.monotonic()
    response = result_of(rig, future)
    waited = time.monotonic() - start  # [s] wall; a guard, not the measurement
    assert response.error_code == ErrorCode.NOT_READY
    assert 'wall time' in response.message and 'is the sim running' in response.message
    assert waited < 10.0
    spin_until(rig.executor, lambda: not rig.received[-1].hold, 10.0, 'the release')


def test_a_restarted_sim_does_not_inherit_the_climb(rig):
    rig.warm_up()
    future = rig.call(**SUCCESSFUL_CLIMB)
    rig.drive(_Deadline(rig, 1.0))
    rig.car = KinematicCar()  # a new sim: the robot at the origin, its clock from 0 again
    rig.warm_up(cycles=5)
    response = result_of(rig, future)
    assert response.error_code == ErrorCode.NOT_READY
    assert 'time went back' in response.message


def test_a_moment_far_ahead_is_not_acted_on(rig):
    rig.warm_up()
    future = rig.call(**SUCCESSFUL_CLIMB)
    rig.drive(_Deadline(rig, 1.0))
    before = len(rig.received)
    real = rig.car.cycles
    rig.car.cycles = (2**31 - 1) * 100  # every input stamped 2^31-1 s, once
    rig.publish_state()
    rig.car.cycles = real
    response = result_of(rig, future)
    assert response.error_code == ErrorCode.NOT_READY
    assert 'leapt' in response.message
    # Nothing was steered on it: the only answers after it stop and release.
    assert all(not m.hold or m.drive_speed == 0.0 for m in rig.received[before:])


@pytest.mark.parametrize('bad', [math.nan, math.inf])
def test_moments_of_non_finite_inputs_are_refused_and_never_reach_a_command(rig, capfd, bad):
    # Every float field of every input non-finite, for one moment every 0.25 s of the climb
    # (in each step), ahead of the real inputs of that moment.
    imu, odom = Imu(), Odometry()
    for vector in (imu.orientation, odom.pose.pose.position, odom.pose.pose.orientation,
                   odom.twist.twist.linear):
        for axis in ('x', 'y', 'z', 'w') if hasattr(vector, 'w') else ('x', 'y', 'z'):
            setattr(vector, axis, bad)
    state = SwivelControllerState(**{name: bad for name in (
        'set_point', 'target', 'measured', 'measured_rate', 'error', 'torque')}, source='hold')
    publish_state = rig.publish_state

    def with_a_bad_moment(*args, **kwargs):
        if rig.car.cycles % 25 == 0:
            state.swivel_command_stamp = rig.heard
            stamp = rclpy.time.Time(nanoseconds=rig.car.cycles * 10_000_000).to_msg()
            for msg, publisher in ((imu, rig.imu), (odom, rig.odom), (state, rig.state)):
                msg.header.stamp = stamp
                publisher.publish(msg)
        publish_state(*args, **kwargs)

    rig.warm_up()
    rig.publish_state = with_a_bad_moment
    response = rig.drive(rig.call(**SUCCESSFUL_CLIMB))
    assert response.success, response.message
    for msg in rig.received:
        assert all(math.isfinite(v) for v in (msg.angle, msg.max_rate, msg.drive_speed)), msg
    log = capfd.readouterr().err
    for line in ('imu refused: orientation.x must be a finite number',
                 'odom refused: pose.pose.position.x must be a finite number',
                 'controller/controller_state refused: set_point must be a finite number'):
        assert line in log, log


def test_a_sim_running_ahead_of_the_first_command_does_not_end_the_climb(rig):
    """
    Check the planner repeats its first command until the controller has heard it.

    Until then the controller does not wait for the planner, so a loaded planner may hear
    its next state seconds later (on a loaded machine); only from then on is a leap
    a fault.
    """
    rig.warm_up()
    future = rig.call(**SUCCESSFUL_CLIMB)
    deadline = time.monotonic() + 10.0
    while not rig.received and time.monotonic() < deadline:
        rig.publish_state(heard=TimeMsg())
        rig.executor.spin_once(timeout_sec=0.05)
    assert rig.received, 'no first command'
    first = rig.received[-1]
    rig.car.cycles += 250  # [10 ms] the sim ran ahead: the controller had not heard it
    rig.publish_state(heard=TimeMsg())
    spin_until(rig.executor, lambda: rig.received[-1] is not first, 10.0, 'the next command')
    repeated = rig.received[-1]
    assert rclpy.time.Time.from_msg(repeated.header.stamp).nanoseconds == rig.car.cycles * 10**7
    assert (repeated.angle, repeated.drive_speed, repeated.hold) == (
        first.angle, first.drive_speed, first.hold)
    rig.car.apply(rig.command)  # the controller heard it now, and waits for the planner
    rig.command = None
    response = rig.drive(future)
    assert response.success, response.message


class _HeldPlans:
    """The planner's make_plan, held until ``release`` for climbs; plan_only plans at once."""

    def __init__(self, monkeypatch):
        self.started = threading.Event()
        self._gate = threading.Event()
        real = planner_node.make_plan

        def make_plan(robot, config, request, whole_car_limit):
            if not request.plan_only:
                self.started.set()
                self._gate.wait(60.0)  # a guard: a failed test must not hang
            return real(robot, config, request, whole_car_limit)

        monkeypatch.setattr(planner_node, 'make_plan', make_plan)

    def release(self):
        self._gate.set()


@pytest.fixture
def held_plans(monkeypatch):
    plans = _HeldPlans(monkeypatch)
    yield plans
    plans.release()


def start_held_climb(rig, held_plans, call):
    rig.warm_up()
    future = call()
    spin_until(rig.executor, held_plans.started.is_set, 10.0, 'the planning')
    return future


def test_the_node_answers_while_a_climb_is_planned(rig, held_plans):
    climb = start_held_climb(rig, held_plans, lambda: rig.call(**SUCCESSFUL_CLIMB))
    # Each answered while the plan is held: the executor is free.
    plan_only = result_of(rig, rig.call(**SUCCESSFUL_CLIMB, plan_only=True))
    assert plan_only.success, plan_only.message
    busy = result_of(rig, rig.call(**SUCCESSFUL_CLIMB))
    assert busy.error_code == ErrorCode.BUSY
    assert 'planned' in busy.message
    assert not send_goal(rig, [], **SUCCESSFUL_CLIMB).accepted
    assert not climb.done() and rig.received == []
    held_plans.release()
    response = rig.drive(climb)
    assert response.success, response.message


def test_a_goal_canceled_while_planned_never_moves(rig, held_plans):
    handle = start_held_climb(rig, held_plans, lambda: send_goal(rig, [], **SUCCESSFUL_CLIMB))
    result_future = handle.get_result_async()
    cancel = handle.cancel_goal_async()
    spin_until(rig.executor, cancel.done, 10.0, 'the cancel response')
    held_plans.release()
    wrapped = result_of(rig, result_future)
    assert wrapped.status == GoalStatus.STATUS_CANCELED
    assert wrapped.result.error_code == ErrorCode.CANCELED
    assert rig.received == []


def publish_reset_event(rig, cycles=None):
    """
    As the sim's reset: the event names the next state, the first of the new world.

    ``cycles``: the control cycle of that state (default: the next one).
    """
    publisher = rig.node.create_publisher(Header, 'sim/reset_event', 10)
    spin_until(rig.executor, lambda: publisher.get_subscription_count() > 0, 10.0,
               'the planner on sim/reset_event')
    cycles = rig.car.cycles if cycles is None else cycles
    publisher.publish(Header(stamp=rclpy.time.Time(nanoseconds=cycles * 10**7).to_msg(),
                             frame_id='world'))
    return cycles * 0.01  # [s]


def test_a_sim_reset_ends_the_climb_with_the_car_stopped(rig):
    rig.warm_up()
    future = rig.call(**SUCCESSFUL_CLIMB)
    rig.drive(_Deadline(rig, 1.0))
    assert rig.received[-1].hold and rig.received[-1].drive_speed > 0.0  # driving
    before = len(rig.received)
    stamp = publish_reset_event(rig)
    response = result_of(rig, future)
    assert response.error_code == ErrorCode.NOT_READY
    assert 'reset' in response.message
    # Only the release, for the new world: drive 0, the controller holds the swivel where it
    # measures it (a hold would turn it to the old world's angle).
    spin_until(rig.executor, lambda: len(rig.received) > before, 10.0, 'the release')
    (release,) = rig.received[before:]
    assert not release.hold and release.drive_speed == 0.0
    assert rclpy.time.Time.from_msg(release.header.stamp).nanoseconds * 1e-9 == \
        pytest.approx(stamp)
    # The world goes on without the climb: its states are not answered.
    rig.warm_up(cycles=5)
    assert len(rig.received) == before + 1


def test_a_sim_reset_while_planned_ends_the_climb_before_it_moves(rig, held_plans):
    climb = start_held_climb(rig, held_plans, lambda: rig.call(**SUCCESSFUL_CLIMB))
    publish_reset_event(rig)
    # Heard before the plan is done: the reset world is not climbed in.
    rig.warm_up(cycles=5)
    held_plans.release()
    response = result_of(rig, climb)
    assert response.error_code == ErrorCode.NOT_READY
    assert 'reset' in response.message
    assert rig.received == []


def test_a_reset_event_heard_late_from_before_the_request_does_not_end_the_climb(
        rig, held_plans):
    # A client reset the sim, saw the new world and asked; the planner heard /clock of the new
    # world before the request, and the reset event (its own topic) only while planning.
    climb = start_held_climb(rig, held_plans, lambda: rig.call(**SUCCESSFUL_CLIMB))
    publish_reset_event(rig, cycles=rig.car.cycles - 20)
    rig.warm_up(cycles=5)
    held_plans.release()
    response = rig.drive(climb)
    assert response.success, response.message


def test_a_reset_event_heard_late_from_before_the_request_does_not_end_a_running_climb(rig):
    rig.warm_up()
    requested = rig.car.cycles
    future = rig.call(**SUCCESSFUL_CLIMB)
    rig.drive(_Deadline(rig, 1.0))
    publish_reset_event(rig, cycles=requested - 20)
    response = rig.drive(future)
    assert response.success, response.message


class _Deadline:
    """A future-like that is done once the rig's car reaches ``seconds`` of sim time."""

    def __init__(self, rig, seconds):
        self._rig, self._end = rig, rig.car.time + seconds

    def done(self):
        return self._rig.car.time >= self._end

    def result(self):
        return None


def test_config_file_matches_the_declared_defaults():
    path = Path(__file__).resolve().parents[1] / 'config' / 'planner_node.yaml'
    values = yaml.safe_load(path.read_text())['/**']['planner']['ros__parameters']
    config = PlannerConfig()
    for item in fields(PlannerConfig):
        assert values[item.name] == pytest.approx(getattr(config, item.name)), item.name
    # The robot is stated once, in the description: the file does not repeat it.
    assert not set(values) & set(description.PARAMETERS)


def test_bad_parameter_is_a_clear_error_at_start():
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=next_domain_id())
    try:
        with pytest.raises(ValueError, match='climb_speed'):
            PlannerNode(context=context,
                        parameter_overrides=[Parameter('climb_speed', value=-1.0)])
    finally:
        rclpy.shutdown(context=context)
