"""
Soak benchmark: the whole ROS stack as `make demo` runs it, for many minutes.

Sim, controller, odometry and planner run as processes, lockstep paced at real time, through
many minutes of driving and repeated climbs. Prints each node's resident memory slope (target
under 1 MB/min) and the message rates it heard.

    scripts/in_ws python scripts/soak.py [--minutes 10] [--domain-id 77]

Each cycle: the sim puts the robot back at the origin with one step ahead, the planner climbs
it (the capability table's height), then the robot drives arcs on flat ground by cmd_vel for
``--drive-seconds`` of sim time. Memory is sampled from /proc every few wall seconds; the
slope is a least-squares line through the samples after the first ``--warm-up`` seconds.
"""

from __future__ import annotations

import argparse
from collections import Counter
import os
import sys
import time

from demo import NODE_PARAMETERS, NODES
from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
import numpy as np
import rclpy
from rclpy.action import ActionClient
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import Imu, JointState
from std_srvs.srv import Empty
from swivel_car_msgs.action import ClimbStep
from swivel_car_msgs.msg import StepObstacle, SwivelCommand, SwivelControllerState
from swivel_car_msgs.srv import ResetSimulation, SpawnObstacle
from swivel_car_planner.core import capability
from swivel_car_ros.ros_params import stamp_to_seconds
from swivel_car_stack import spin_until, start_node

STEP_DISTANCE = 1.2  # [m] ahead of the front axle after each reset
SAMPLE_PERIOD = 5.0  # [s] wall between memory samples
# (v [m/s], omega [rad/s]) in turn.
ARCS = ((0.3, 0.5), (0.3, -0.5), (0.0, 0.8), (0.2, 0.0))
TOPICS = {'joint_states': JointState, 'imu': Imu, 'odom': Odometry,
          'ground_truth/odom': Odometry, 'controller/controller_state': SwivelControllerState,
          'swivel_command': SwivelCommand}


def rss_mb(pid: int) -> float:
    """Resident set size of a process [MB]."""
    with open(f'/proc/{pid}/status') as status:
        for line in status:
            if line.startswith('VmRSS:'):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError(f'no VmRSS for process {pid}')


class SoakNode(Node):
    """The user's side: counts every message, drives, asks for climbs."""

    def __init__(self, context) -> None:
        super().__init__('soak', context=context,
                         parameter_overrides=[Parameter('use_sim_time', value=True)])
        self.counts: Counter[str] = Counter()
        self.sim_time = 0.0  # [s] stamp of the newest joint_states
        for topic, kind in TOPICS.items():
            self.create_subscription(kind, topic, lambda msg, t=topic: self._count(t, msg), 100)
        self.cmd_vel = self.create_publisher(TwistStamped, 'cmd_vel', 10)
        self.reset_sim = self.create_client(ResetSimulation, 'sim/reset')
        self.reset_odom = self.create_client(Empty, 'odometry/reset')
        self.spawn = self.create_client(SpawnObstacle, 'sim/spawn_obstacle')
        self.climb = ActionClient(self, ClimbStep, 'climb_step')

    def _count(self, topic: str, msg) -> None:
        self.counts[topic] += 1
        if topic == 'joint_states':
            self.sim_time = stamp_to_seconds(msg.header.stamp)

    def drive(self, v: float, omega: float) -> None:
        msg = TwistStamped()
        msg.header.frame_id = 'base_link'
        msg.twist.linear.x, msg.twist.angular.z = v, omega
        self.cmd_vel.publish(msg)


class Soak:

    def __init__(self, args: argparse.Namespace) -> None:
        self.args = args
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
        self.processes = [start_node(package, executable, args.domain_id,
                                     NODE_PARAMETERS[executable])
                          for package, executable in NODES]
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=args.domain_id)
        self.node = SoakNode(self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.samples: list[tuple[float, list[float]]] = []  # (wall [s], RSS per process [MB])
        self.start = time.monotonic()
        self.next_sample = self.start
        self.climbs: Counter[str] = Counter()

    def spin(self, condition, timeout: float, what: str) -> None:
        def done() -> bool:
            for process in self.processes:
                if not process.running():
                    raise RuntimeError(f'{process.name} exited:\n{process.output()[-3000:]}')
            now = time.monotonic()
            if now >= self.next_sample:
                self.samples.append((now - self.start,
                                     [rss_mb(p.process.pid) for p in self.processes]))
                self.next_sample = now + SAMPLE_PERIOD
            return condition()
        spin_until(self.executor, done, timeout, what)

    def call(self, client, request, what: str):
        future = client.call_async(request)
        self.spin(future.done, 30.0, what)
        return future.result()

    def climb_cycle(self, height: float) -> None:
        node = self.node
        result = self.call(node.reset_sim, ResetSimulation.Request(remove_obstacles=True),
                           'sim/reset')
        if not result.success:
            raise RuntimeError(f'sim/reset failed: {result.message}')
        self.call(node.reset_odom, Empty.Request(), 'odometry/reset')
        obstacle = StepObstacle(name='soak_step', height=height, depth=1.0, width=2.4,
                                distance=STEP_DISTANCE, yaw=0.0, friction=1.0)
        result = self.call(node.spawn, SpawnObstacle.Request(obstacle=obstacle),
                           'sim/spawn_obstacle')
        if not result.success:
            raise RuntimeError(f'spawning the step failed: {result.message}')
        goal = ClimbStep.Goal(step_height=height, step_distance=STEP_DISTANCE, step_yaw=0.0,
                              step_width=2.4, plan_only=False, time_allowance=60.0)
        sent = node.climb.send_goal_async(goal)
        self.spin(sent.done, 30.0, 'goal acceptance')
        if not sent.result().accepted:
            self.climbs['rejected'] += 1
            return
        finished = sent.result().get_result_async()
        self.spin(finished.done, 300.0, 'the climb')
        result = finished.result().result
        self.climbs[result.error_code] += 1
        if result.error_code:
            print(f'climb failed ({result.error_code}): {result.message}', flush=True)

    def drive_cycle(self) -> None:
        self.call(self.node.reset_sim, ResetSimulation.Request(remove_obstacles=True),
                  'sim/reset')
        for v, omega in ARCS:
            end = self.node.sim_time + self.args.drive_seconds / len(ARCS)
            while self.node.sim_time < end:
                self.node.drive(v, omega)
                sim_time = self.node.sim_time
                self.spin(lambda t=sim_time: self.node.sim_time > t + 0.05, 30.0, 'driving')
        self.node.drive(0.0, 0.0)

    def run(self) -> None:
        node = self.node
        height = capability.table_for(capability.INSTALLED)[0].limit
        self.spin(lambda: node.spawn.service_is_ready() and node.climb.server_is_ready()
                  and node.reset_odom.service_is_ready() and node.counts['odom'] > 0, 90.0,
                  'the stack to come up')
        # The planner hears its inputs a moment after this node does: before, it would
        # rightly answer NOT_READY.
        first = node.sim_time
        self.spin(lambda: node.sim_time > first + 1.0, 60.0, 'a second of sim time')
        start_counts, start_sim = Counter(node.counts), node.sim_time
        cycles = 0
        while time.monotonic() - self.start < 60.0 * self.args.minutes:
            self.climb_cycle(height)
            self.drive_cycle()
            cycles += 1
            print(f'{(time.monotonic() - self.start) / 60.0:5.1f} min: {cycles} cycles, '
                  f'climbs {dict(self.climbs)}', flush=True)
        self.report(height, cycles, start_counts, start_sim)

    def report(self, height, cycles, start_counts, start_sim) -> None:
        wall = time.monotonic() - self.start
        sim = self.node.sim_time - start_sim
        print(f'\nsoak: {wall / 60.0:.1f} min wall, {sim / 60.0:.1f} min sim, {cycles} cycles '
              f'(a {height:.2f} m climb and {self.args.drive_seconds:.0f} s of driving each); '
              f'climb results by error code (0 = climbed): {dict(self.climbs)}')
        kept = [(t, rss) for t, rss in self.samples if t >= self.args.warm_up]
        times = np.array([t for t, _ in kept]) / 60.0  # [min]
        print(f'resident memory, {len(kept)} samples after the first {self.args.warm_up:.0f} s '
              f'(target: slope under 1 MB/min)')
        print('node                              start MB   end MB   slope MB/min')
        for i, process in enumerate(self.processes):
            rss = np.array([sample[i] for _, sample in kept])
            slope = np.polyfit(times, rss, 1)[0] if len(kept) >= 2 else float('nan')
            print(f'{process.name:32s} {rss[0]:9.1f} {rss[-1]:8.1f} {slope:+14.3f}')
        print('messages heard by the soak node    per sim s   per wall s')
        for topic in TOPICS:
            count = self.node.counts[topic] - start_counts[topic]
            print(f'{topic:32s} {count / max(sim, 1e-9):11.1f} {count / wall:11.1f}')

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        codes = {process.name: process.stop() for process in self.processes}
        print(f'exit codes: {codes}')


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--minutes', type=float, default=10.0, help='wall time to run')
    parser.add_argument('--drive-seconds', type=float, default=20.0,
                        help='sim seconds of driving arcs per cycle')
    parser.add_argument('--warm-up', type=float, default=60.0,
                        help='wall seconds left out of the memory slope')
    parser.add_argument('--domain-id', type=int, default=77)
    args = parser.parse_args(argv)
    if not (args.minutes > 0.0 and args.drive_seconds > 0.0 and args.warm_up >= 0.0):
        parser.error('--minutes and --drive-seconds must be > 0, --warm-up >= 0')
    soak = Soak(args)
    try:
        soak.run()
    except KeyboardInterrupt:
        return 130
    finally:
        soak.close()
    return 0


if __name__ == '__main__':
    sys.exit(main())
