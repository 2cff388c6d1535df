"""The whole stack as a user runs it: the four installed node executables, each in its own
process, on sim time in lockstep. Driven through cmd_vel and climb_step; judged by the sim's
ground truth."""

from __future__ import annotations

import math
from typing import Iterator

import pytest
from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from swivel_car_model.params import SwivelCarParams
from swivel_car_msgs.msg import StepObstacle, SwivelControllerState
from swivel_car_msgs.srv import ClimbStep, SpawnObstacle
from sim_session import GroundTruth
from swivel_car_testing import NodeProcess, lockstep_parameters, spin_until, start_node

NODES = {'sim': ('swivel_car_sim', 'sim_node'),
         'controller': ('swivel_car_control', 'controller_node'),
         'odometry': ('swivel_car_control', 'odometry_node'),
         'planner': ('swivel_car_planner', 'planner_node')}
# A killed controller must not freeze the lockstep sim for long: after this many wall seconds
# without a command it steps on with its watchdog.
LOCKSTEP_TIMEOUT = 0.1  # [s]


class Stack:
    """The four node processes and a user node that drives and watches the ground truth."""

    def __init__(self, domain_id: int, context) -> None:
        self.domain_id = domain_id
        self.processes = {name: self.start(name) for name in NODES}
        self.user = Node('user', context=context,
                         parameter_overrides=[Parameter('use_sim_time', value=True)])
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(self.user)
        self.truth: list[Odometry] = []
        self.clock: list[Clock] = []
        self.user.create_subscription(Odometry, 'ground_truth/odom', self.truth.append, 100)
        self.user.create_subscription(Clock, '/clock', self.clock.append, 100)
        self.controller_states: list[SwivelControllerState] = []
        self.user.create_subscription(SwivelControllerState, 'controller/controller_state',
                                      self.controller_states.append, 100)
        self.cmd_vel = self.user.create_publisher(TwistStamped, 'cmd_vel', 10)
        self.spawn = self.user.create_client(SpawnObstacle, 'sim/spawn_obstacle')
        self.climb = self.user.create_client(ClimbStep, 'climb_step')

    def start(self, name: str) -> NodeProcess:
        package, executable = NODES[name]
        # Paced at real time: this test's node, outside the lockstep chain, drives with
        # cmd_vel and judges the car the moment after a kill, and before a climb the planner
        # is outside it too (unpaced, it fell behind once: "no complete input").
        return start_node(package, executable, self.domain_id, {
            'use_sim_time': True, **lockstep_parameters(executable, LOCKSTEP_TIMEOUT)})

    def spin_until(self, condition, timeout: float = 60.0, what: str = 'condition') -> None:
        def checked() -> bool:
            for name, process in self.processes.items():
                assert process.running(), f'{name} died:\n{process.output()[-3000:]}'
            return condition()
        spin_until(self.executor, checked, timeout, what)

    def sim_time(self) -> float:
        stamp = self.truth[-1].header.stamp
        return stamp.sec + 1e-9 * stamp.nanosec

    def wait_sim_time(self, duration: float, what: str) -> None:
        end = self.sim_time() + duration
        self.spin_until(lambda: self.sim_time() >= end, 120.0, what)

    def drive(self, speed: float, duration: float) -> None:
        """Publish cmd_vel at 20 Hz of sim time for ``duration`` sim seconds."""
        end = self.sim_time() + duration
        while self.sim_time() < end:
            # A zero stamp: the controller stamps it on receipt, so a moment's lag of this
            # node behind the sim cannot make the command look stale to the deadman.
            msg = TwistStamped()
            msg.twist.linear.x = speed
            self.cmd_vel.publish(msg)
            self.wait_sim_time(0.05, 'sim time while driving')

    def wait_planner_ready(self) -> None:
        """Until the planner hears the whole stack: a climb out of reach is refused as
        unreachable (without motion), not as NOT_READY. (A plan-only request is answered
        before the planner hears anything.)"""
        self.spin_until(self.climb.service_is_ready, 60.0, 'the climb_step service')
        while True:
            future = self.climb.call_async(ClimbStep.Request(
                step_height=10.0, step_distance=1.0, step_yaw=0.0, plan_only=False))
            self.spin_until(future.done, 30.0, 'a refusal')
            if future.result().error_code != ClimbStep.Response.ERROR_NOT_READY:
                assert future.result().error_code == \
                    ClimbStep.Response.ERROR_UNREACHABLE_HEIGHT, future.result().message
                return
            self.wait_sim_time(0.2, 'the planner to hear the stack')

    def kill_mid_climb(self, name: str):
        """Ask for a 4 cm climb, kill -9 node ``name`` once the car drives; returns the
        climb's future."""
        self.wait_planner_ready()
        climb = self.climb.call_async(ClimbStep.Request(
            step_height=0.04, step_distance=1.0, step_yaw=0.0, plan_only=False))
        self.spin_until(lambda: self.speed() > 0.1 or climb.done(), 60.0, 'the climb to drive')
        assert not climb.done(), climb.result().message
        self.processes.pop(name).kill()
        return climb

    def x(self) -> float:
        return self.truth[-1].pose.pose.position.x

    def speed(self) -> float:
        return abs(self.truth[-1].twist.twist.linear.x)

    def close(self) -> None:
        self.executor.shutdown()
        self.user.destroy_node()
        for process in self.processes.values():
            process.stop()


@pytest.fixture
def stack(ros_domain) -> Iterator[Stack]:
    domain_id, context = ros_domain
    running = Stack(domain_id, context)
    try:
        running.spin_until(lambda: running.truth and running.controller_states
                           and running.climb.service_is_ready()
                           and running.spawn.service_is_ready(), 90.0, 'the stack to start')
        yield running
    finally:
        running.close()


def test_drive_then_climb_a_step(stack: Stack):
    stack.wait_planner_ready()
    start = stack.x()
    stack.drive(0.3, 2.0)
    assert stack.x() - start > 0.4, 'cmd_vel did not move the car forward'

    p = SwivelCarParams()
    # The planner needs room to turn to its approach heading; the rear axle climbs up to
    # 4 cm by traction (see swivel_car_planner's README).
    height, distance = 0.04, 1.0
    edge_x = stack.x() + p.wheelbase + distance
    spawned = stack.spawn.call_async(SpawnObstacle.Request(obstacle=StepObstacle(
        name='step', height=height, depth=1.5, width=1.6, distance=distance, yaw=0.0,
        friction=1.0)))
    stack.spin_until(spawned.done, 30.0, 'spawn_obstacle')
    assert spawned.result().success, spawned.result().message

    # Asked while still rolling on the last cmd_vel: the planner stops the car first.
    assert stack.speed() > 0.2
    response = stack.climb.call_async(ClimbStep.Request(
        step_height=height, step_distance=edge_x - p.wheelbase - stack.x(), step_yaw=0.0,
        plan_only=False))
    stack.spin_until(response.done, 600.0, 'climb_step')
    result = response.result()
    assert result.success, f'{result.error_code}: {result.message}'
    final = GroundTruth.from_msg(stack.truth[-1])
    assert final.four_wheels_on_top(height, p.r), final
    # The rear wheels' contacts are past the edge whatever the car's heading (x forward).
    assert final.x - p.h * abs(math.sin(final.yaw)) > edge_x, (final, edge_x)


def test_killed_controller_stops_the_car_and_a_restart_recovers(stack: Stack):
    stack.drive(0.3, 1.0)
    assert stack.speed() > 0.2
    stack.processes.pop('controller').kill()
    # The sim keeps running on its lockstep timeout; its watchdog stops the drive.
    clock_before = len(stack.clock)
    stack.wait_sim_time(1.5, 'the sim to go on without a controller')
    assert len(stack.clock) > clock_before
    assert stack.speed() < 0.02
    assert all(process.running() for process in stack.processes.values())

    stack.processes['controller'] = stack.start('controller')
    x_before = stack.x()
    stack.drive(0.3, 5.0)
    assert stack.x() > x_before + 0.5, (
        f"the restarted controller did not drive the car:\n"
        f"{stack.processes['controller'].output()[-3000:]}")
    stack.drive(0.0, 1.0)
    assert stack.speed() < 0.01, 'a zero cmd_vel did not stop the car'


def test_killed_planner_mid_climb_stops_the_car_and_a_restart_recovers(stack: Stack):
    climb = stack.kill_mid_climb('planner')
    # The controller's swivel_command deadman (0.5 s) stops the drive.
    stack.wait_sim_time(1.5, 'the car to stop without a planner')
    assert stack.speed() < 0.02
    assert not climb.done()  # its server is gone; the client gives up on its own
    states = stack.controller_states
    assert states[-1].source == 'hold' and states[-1].drive_speed == 0.0

    stack.spin_until(lambda: not stack.climb.service_is_ready(), 30.0, 'the planner to go')
    stack.processes['planner'] = stack.start('planner')
    stack.wait_planner_ready()


def test_killed_sim_mid_climb_ends_the_climb_and_a_new_sim_inherits_nothing(stack: Stack):
    climb = stack.kill_mid_climb('sim')
    # Sim time stands still: the planner ends the climb on wall time (ready_timeout 1 s).
    stack.spin_until(climb.done, 10.0, 'the climb to end without a sim')
    assert climb.result().error_code == ClimbStep.Response.ERROR_NOT_READY
    assert 'is the sim running' in climb.result().message

    # A new sim (its clock from 0, the robot at the origin): nothing drives it on its own...
    truth_before = len(stack.truth)
    stack.processes['sim'] = stack.start('sim')
    stack.spin_until(lambda: len(stack.truth) > truth_before, 60.0, 'the new sim')
    stack.wait_sim_time(1.5, 'the new sim to run')
    assert abs(stack.x()) < 0.01 and stack.speed() < 0.01
    # ...and the stack drives it when asked.
    stack.drive(0.3, 3.0)
    assert stack.x() > 0.3, stack.processes['controller'].output()[-3000:]


def test_killed_odometry_mid_climb_ends_the_climb_and_a_restart_recovers(stack: Stack):
    climb = stack.kill_mid_climb('odometry')
    stack.spin_until(climb.done, 30.0, 'the climb to end without odometry')
    assert climb.result().error_code == ClimbStep.Response.ERROR_NOT_READY
    assert 'odom' in climb.result().message
    stack.wait_sim_time(1.0, 'the car to stop')
    assert stack.speed() < 0.02

    stack.processes['odometry'] = stack.start('odometry')
    stack.wait_planner_ready()
