"""
The whole stack in the real pybullet sim, for system tests and the benchmark.

``SimSession`` starts sim_node (lockstep), controller_node, odometry_node and planner_node as
processes on a fresh ROS domain, each with its package's installed config, and gives an
in-process client: spawn a step, reset the sim, call climb_step (service or action), read the
ground truth. Processes come from the repository's scripts/swivel_car_stack.py.
"""

from __future__ import annotations

import itertools
import math
import os
from pathlib import Path
import sys
import time
from typing import Any, Callable

from builtin_interfaces.msg import Time as TimeMsg
from nav_msgs.msg import Odometry
import rclpy
from rclpy.action import ActionClient
from rclpy.experimental import EventsExecutor
from std_srvs.srv import Empty, SetBool
from swivel_car_model.description import CarDescription
from swivel_car_msgs.action import ClimbStep as ClimbStepAction
from swivel_car_msgs.msg import StepObstacle, SwivelCommand, SwivelControllerState
from swivel_car_msgs.srv import ClimbStep, ResetSimulation, SpawnObstacle, StepSimulation
from swivel_car_planner.ground_truth import GroundTruth
from swivel_car_ros.lockstep import stamp_ns

try:
    from swivel_car_testing import next_domain_id, spin_until
except ImportError:  # outside pytest: the repository's helpers (pytest.ini puts them on the path)
    _REPO = Path(__file__).resolve().parents[2]
    sys.path += [str(_REPO / 'scripts'), str(_REPO / 'tests' / 'support')]
    from swivel_car_testing import next_domain_id, spin_until
from swivel_car_stack import lockstep_parameters, NodeProcess, ResentRequest, start_node

CLIMB_WALL_LIMIT = 600.0  # [s] guard against a hung stack, not a measurement
# [s] wall; half of it the controller waits for the planner. A loaded CI machine held a
# node up for seconds: within it, the climb stays deterministic.
LOCKSTEP_TIMEOUT = 6.0
RESEND_AFTER = 5.0  # [s] wall


class SimSession:
    """
    The stack on its own ROS domain, and a client node to drive it.

    Parameters
    ----------
    robot_variant : str
        The sim's robot: 'swivel' or 'car_like'.
    planner_parameters : mapping
        ``-p`` overrides for planner_node.
    planner : bool
        Start planner_node (the car-like baseline is driven with cmd_vel only).
    sim_parameters : mapping
        ``-p`` overrides for sim_node, on top of the lockstep ones. The sim starts paused
        (``start_paused``); `wait_ready` resumes it.

    """

    def __init__(self, robot_variant: str = 'swivel',
                 planner_parameters: dict[str, Any] | None = None,
                 planner: bool = True,
                 sim_parameters: dict[str, Any] | None = None,
                 robot_parameters: dict[str, Any] | None = None) -> None:
        """
        Start the stack and the client node.

        ``robot_parameters``: robot description values for every node (a design file's
        ``ros__parameters``); unset = the installed configs' description.
        """
        self.domain_id = next_domain_id()
        robot = dict(robot_parameters or {})
        description = CarDescription.from_values(robot)
        self.wheel_radius = description.r  # [m]
        self.wheelbase = description.wheelbase  # [m]
        # The car-like baseline steers a turntable joint; the controller drives it the same way.
        joint = {'swivel_joint': 'steering_joint' if robot_variant == 'car_like'
                 else 'swivel_joint'}
        sim_time = {'use_sim_time': True}
        # In the lockstep chain the planner's climbs do not depend on the machine's load, and
        # nothing outside it drives the car: the sim runs as fast as the chain answers.
        # Paused until this node has discovered the stack (some 2.3 s after the sim is up): an
        # unpaced sim otherwise ran 20-45 s of sim time for nothing meanwhile.
        sim = {'robot_variant': robot_variant, 'start_paused': True, **robot}
        specs = [('swivel_car_sim', 'sim_node', sim),
                 ('swivel_car_control', 'controller_node', {**sim_time, **joint, **robot}),
                 ('swivel_car_control', 'odometry_node', {**sim_time, **joint, **robot})]
        if planner:
            specs.append(('swivel_car_planner', 'planner_node',
                          {**sim_time, **robot, **(planner_parameters or {})}))
        self.processes: list[NodeProcess] = []
        try:
            for package, executable, parameters in specs:
                overrides = sim_parameters if executable == 'sim_node' else None
                self.processes.append(start_node(
                    package, executable, self.domain_id,
                    {**parameters, **lockstep_parameters(executable, LOCKSTEP_TIMEOUT,
                                                         real_time_factor=0.0),
                     **(overrides or {})}))
            os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
            self.context = rclpy.Context()
            rclpy.init(context=self.context, domain_id=self.domain_id)
            self.node = rclpy.create_node('climb_client', context=self.context)
            self.executor = EventsExecutor(context=self.context)
            self.executor.add_node(self.node)
        except BaseException:
            self._stop_processes()
            raise
        self.truth: GroundTruth | None = None
        self.time = 0.0  # [s] sim time of the last ground truth
        self.controller_state: SwivelControllerState | None = None
        self.odom_count = 0
        self.node.create_subscription(Odometry, 'ground_truth/odom', self._on_truth, 10)
        self.node.create_subscription(Odometry, 'odom', self._on_odom, 10)
        self.node.create_subscription(SwivelControllerState, 'controller/controller_state',
                                      self._on_controller_state, 10)
        self.spawn_client = self.node.create_client(SpawnObstacle, 'sim/spawn_obstacle')
        self.reset_client = self.node.create_client(ResetSimulation, 'sim/reset')
        self.pause_client = self.node.create_client(SetBool, 'sim/set_paused')
        self.run_client = self.node.create_client(StepSimulation, 'sim/run')
        self.odometry_reset = self.node.create_client(Empty, 'odometry/reset')
        self.climb_client = self.node.create_client(ClimbStep, 'climb_step')
        self.climb_action = ActionClient(self.node, ClimbStepAction, 'climb_step')
        self.swivel_command = self.node.create_publisher(SwivelCommand, 'swivel_command', 10)
        self._planner = planner
        self._step_names = itertools.count()  # numbers the steps asked for

    def _on_truth(self, msg: Odometry) -> None:
        self.truth = GroundTruth.from_msg(msg)
        self.time = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec

    def _on_odom(self, msg: Odometry) -> None:
        self.odom_count += 1

    def _on_controller_state(self, msg: SwivelControllerState) -> None:
        self.controller_state = msg

    def spin_until(self, condition: Callable[[], bool], timeout: float, what: str) -> None:
        spin_until(self.executor, condition, timeout, what, self.processes)

    def wait_ready(self, timeout: float = 60.0) -> None:
        """
        Wait until the stack's services are up, resume the sim, wait until it runs.

        Running: the sim, the controller and the odometry publish, and the planner hears them.
        """
        clients = [self.spawn_client, self.reset_client, self.pause_client, self.run_client,
                   self.odometry_reset]
        if self._planner:
            clients.append(self.climb_client)
        self.spin_until(lambda: all(c.service_is_ready() for c in clients), timeout,
                        'the services of the stack')
        self.set_paused(False)
        self.spin_until(lambda: (self.truth is not None and self.odom_count > 0
                                 and self.controller_state is not None),
                        timeout, 'the stack (sim, controller, odometry, planner)')
        if self._planner:
            self.spin_until(self.climb_action.server_is_ready, timeout, 'the climb action')
            # The planner hears the stack too: a step out of reach is refused as unreachable,
            # without motion, once it is ready. Refused either way, it may be asked twice: a
            # planner that had not yet discovered this node's response reader dropped the
            # answer, and the wait for it ran into the test's timeout (BUSY: a copy's answer
            # came first while the planner still had the other).
            deadline = time.monotonic() + timeout
            out_of_reach = ClimbStep.Request(step_height=10.0, step_distance=1.0)
            while self.call(self.climb_client, out_of_reach, resend=True).error_code in (
                    ClimbStep.Response.ERROR_NOT_READY, ClimbStep.Response.ERROR_BUSY):
                if time.monotonic() > deadline:
                    raise AssertionError('the planner never got ready')
                self.settle(0.2)

    def call(self, client, request, timeout: float = 30.0, resend: bool = False):
        """
        Return the service's response.

        ``resend``: for a request that may come twice, sent again every ``RESEND_AFTER`` wall
        seconds until one is answered (``ResentRequest``).
        """
        call = ResentRequest(client, request, RESEND_AFTER if resend else math.inf)
        self.spin_until(call.done, timeout, f'{client.srv_name}')
        return call.result()

    def reset(self, x: float = 0.0, y: float = 0.0, yaw: float = 0.0) -> None:
        """
        Put the robot back at rest at the pose, swivel at 0, obstacles removed, odometry zeroed.

        The controller starts afresh from the reset state (sim/reset_event).
        """
        response = self.call(self.reset_client, ResetSimulation.Request(
            x=x, y=y, yaw=yaw, remove_obstacles=True), resend=True)
        if not response.success:
            raise RuntimeError(f'sim reset failed: {response.message}')
        self.settle(0.3)
        self.call(self.odometry_reset, Empty.Request(), resend=True)
        self.settle(0.2)

    def set_paused(self, paused: bool) -> None:
        response = self.call(self.pause_client, SetBool.Request(data=paused), resend=True)
        if not response.success:
            raise RuntimeError(f'sim set_paused failed: {response.message}')

    def run(self, steps: int) -> TimeMsg:
        """
        Run ``steps`` physics steps (whole control periods) and hold the sim paused there.

        Returns the stamp of the state it paused at, once the controller has answered it,
        whatever the machine's speed: where the sim stops does not depend on when this node
        acts.
        """
        response = self.call(self.run_client, StepSimulation.Request(steps=steps))
        if not response.success:
            raise RuntimeError(f'sim run failed: {response.message}')
        end = stamp_ns(response.sim_time)  # [ns]

        def answered() -> bool:
            return stamp_ns(self.controller_state.header.stamp) >= end

        self.spin_until(answered, 60.0, f'the sim to run until {end * 1e-9:.3f} s')
        return response.sim_time

    def settle(self, seconds: float) -> None:
        """Let ``seconds`` of sim time pass while spinning (the sim keeps stepping)."""
        end = self.time + seconds
        self.spin_until(lambda: self.time >= end, 60.0 + 10.0 * seconds, 'sim time to pass')

    def spawn_step(self, height: float, distance: float, yaw: float = 0.0,
                   depth: float = 2.0, width: float = 3.0, friction: float = 1.0) -> str:
        # Named, so that a resent request whose first was spawned is told so.
        name = f'session_step_{next(self._step_names)}'
        response = self.call(self.spawn_client, SpawnObstacle.Request(obstacle=StepObstacle(
            name=name, height=height, depth=depth, width=width, distance=distance, yaw=yaw,
            friction=friction)), resend=True)
        if not response.success and response.message.endswith(
                f'an obstacle named {name!r} exists already'):
            return name
        if not response.success:
            raise RuntimeError(f'spawn failed: {response.message}')
        return response.name

    def climb(self, height: float, distance: float, yaw: float = 0.0,
              plan_only: bool = False, width: float = 0.0) -> ClimbStep.Response:
        """Call the climb_step service as users do; return when the climb ends."""
        return self.call(self.climb_client, ClimbStep.Request(
            step_height=height, step_distance=distance, step_yaw=yaw, plan_only=plan_only,
            step_width=width), timeout=CLIMB_WALL_LIMIT)

    def drive_straight(self, drive_speed: float, seconds: float) -> None:
        """
        Hold the steering at 0 and drive for ``seconds`` of sim time, then stop.

        The command is repeated within the controller's swivel_command deadman.
        """
        for speed, duration in ((drive_speed, seconds), (0.0, 0.5)):
            end = self.time + duration
            while self.time < end:
                self.swivel_command.publish(
                    SwivelCommand(angle=0.0, drive_speed=speed, hold=True))
                self.settle(0.1)
        self.swivel_command.publish(SwivelCommand(hold=False))

    def front_on_top(self, height: float, tolerance: float = 0.015) -> bool:
        """Ground truth: the front axle (wheelbase ahead of base_link) at step height."""
        return self.truth.front_on_top(height, self.wheel_radius, self.wheelbase, tolerance)

    def four_wheels_on_top(self, height: float, tolerance: float = 0.01) -> bool:
        return self.truth is not None and self.truth.four_wheels_on_top(
            height, self.wheel_radius, tolerance)

    def close(self) -> list[str]:
        """Stop everything; returns the logs of processes that died on their own."""
        crashed = [f'{p.name}:\n{p.output()}' for p in self.processes if not p.running()]
        try:
            self.climb_action.destroy()
            self.node.destroy_node()
            rclpy.try_shutdown(context=self.context)
        finally:
            self._stop_processes()
        return crashed

    def _stop_processes(self) -> None:
        for process in reversed(self.processes):
            process.stop()
