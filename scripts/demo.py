#!/usr/bin/env python3
"""
The main job: the simulated swivel car drives to a step, finds it and climbs it.

Starts the stack the way a user would with `ros2 run`: the installed `sim_node`,
`controller_node`, `odometry_node`, `planner_node` and `step_detector_node`, each in its
own process, headless, on sim time, in lockstep. Then, like a user: spawns a step in front
of the car, drives towards it with velocity commands on `cmd_vel`, and asks the planner to
climb the step the car detected through the `climb_step` action (`use_detected_step`):
nobody tells the planner where the step is. Prints a progress line while it runs and a
summary at the end, and writes a report (plots, rendered frames, the depth image and the
detection beside the truth, index.md) to the report folder. Exit code 0 only if the climb
succeeded.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
import shutil
import sys
import time

from demo_report import read_bag, Recording, write_report
from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
import numpy as np
import rclpy
from rclpy.action import ActionClient
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image
from swivel_car_msgs.action import ClimbStep
from swivel_car_msgs.msg import DetectedStep, StepObstacle
from swivel_car_msgs.srv import SpawnObstacle
from swivel_car_planner.core import capability
from swivel_car_ros.ros_params import stamp_to_seconds
from swivel_car_sim.world import StepSpec
from swivel_car_stack import (
    lockstep_parameters, NodeProcess, REPO_ROOT, spin_until, start_node)

NODES = (('swivel_car_sim', 'sim_node'), ('swivel_car_control', 'controller_node'),
         ('swivel_car_control', 'odometry_node'), ('swivel_car_planner', 'planner_node'),
         ('swivel_car_perception', 'step_detector_node'))
# What the recorder must have subscribed to before the demo moves (it records every topic;
# the report is drawn from the bag).
RECORDED = ('/clock', '/joint_states', '/ground_truth/odom', '/odom',
            '/controller/controller_state', '/cmd_vel', '/robot_description',
            '/climb_step/_action/feedback')

# Lockstep: the physics advances only when the controller has answered, and the controller
# takes the planner's commands in step, so the climb does not depend on how busy the machine
# is. Paced at real time, so that the demo's own node (it drives by cmd_vel, outside the
# lockstep) keeps up.
LOCKSTEP_TIMEOUT = 0.5  # [s] wall
NODE_PARAMETERS = {executable: {'use_sim_time': True,
                                **lockstep_parameters(executable, LOCKSTEP_TIMEOUT)}
                   for _, executable in NODES}
NODE_PARAMETERS['sim_node']['gui'] = False
# As the robot runs (--clock wall, `make demo CLOCK=wall`): the sim stamps with the system
# clock and has the hardware's sensors and links, no /clock, no lockstep, every node on the
# system clock (stack.launch.py clock_source:=wall sensor_profile:=realistic).
WALL_PARAMETERS = {executable: {'use_sim_time': False} for _, executable in NODES}
WALL_PARAMETERS['sim_node'].update(gui=False, clock_source='wall', sensor_profile='realistic')


class DemoNode(Node):
    """The user's side of the demo: records, spawns the step, drives, asks for the climb."""

    def __init__(self, context, use_sim_time: bool = True) -> None:
        super().__init__('demo', context=context,
                         parameter_overrides=[Parameter('use_sim_time', value=use_sim_time)])
        self.recording = Recording()
        self.create_subscription(Odometry, 'ground_truth/odom', self._on_truth, 100)
        self.create_subscription(Odometry, 'odom', self._on_odom, 100)
        self.cmd_vel = self.create_publisher(TwistStamped, 'cmd_vel', 10)
        self.spawn = self.create_client(SpawnObstacle, 'sim/spawn_obstacle')
        self.climb = ActionClient(self, ClimbStep, 'climb_step')
        self.detections: list[DetectedStep] = []
        self.depth: Image | None = None  # the camera's last frame
        self.create_subscription(DetectedStep, 'detected_step', self.detections.append, 10)
        self.create_subscription(Image, 'camera/depth/image_rect_raw', self._on_depth,
                                 qos_profile_sensor_data)

    def _on_depth(self, msg: Image) -> None:
        self.depth = msg

    def recorded(self, topics) -> bool:
        """Whether the recorder subscribes to every one of ``topics``."""
        return all(any(info.node_name == 'recorder'
                       for info in self.get_subscriptions_info_by_topic(topic))
                   for topic in topics)

    def _on_truth(self, msg: Odometry) -> None:
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        self.recording.truth.append(
            (stamp_to_seconds(msg.header.stamp), p.x, p.y, p.z, q.x, q.y, q.z, q.w))

    def _on_odom(self, msg: Odometry) -> None:
        p = msg.pose.pose.position
        self.recording.odom.append((stamp_to_seconds(msg.header.stamp), p.x, p.y))

    def drive(self, speed: float) -> None:
        msg = TwistStamped()
        # A zero stamp: the controller stamps the command on receipt, so a moment's lag of
        # the demo (it follows two topics at 100 Hz) cannot make it look stale.
        msg.header.frame_id = 'base_link'
        msg.twist.linear.x = speed
        self.cmd_vel.publish(msg)


class Progress:
    """
    One progress line.

    Rewritten in place on a terminal; otherwise a line whenever the phase changes and every
    few seconds.
    """

    PERIOD = 3.0  # [s] wall, between lines when not on a terminal

    def __init__(self) -> None:
        self._tty = sys.stdout.isatty()
        self._phase = ''
        self._printed = 0.0

    def show(self, phase: str, text: str) -> None:
        line = f'[{phase:>10}] {text}'
        if self._tty:
            sys.stdout.write('\r' + line.ljust(100)[:100])
            sys.stdout.flush()
        elif phase != self._phase or time.monotonic() - self._printed > self.PERIOD:
            print(line, flush=True)
            self._printed = time.monotonic()
        self._phase = phase

    def done(self) -> None:
        if self._tty:
            sys.stdout.write('\n')


class DemoError(RuntimeError):
    """The demo could not do what it set out to do."""


def demo_step(args: argparse.Namespace) -> StepSpec:
    """Return the step the demo spawns, square across the car's path."""
    return StepSpec(name='demo_step', height=args.step_height, depth=1.0, width=2.4,
                    distance=args.step_distance, yaw=0.0, friction=1.0)


def run_demo(args: argparse.Namespace, progress: Progress) -> tuple[dict, Recording]:
    """
    Start the stack, drive to the step, climb it.

    Returns the summary figures and what was recorded.
    """
    domain_id = args.domain_id
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    # Beside the stack, as `stack.launch.py record:=true` starts them: the robot model on the
    # graph and the recorder.
    shutil.rmtree(args.report / 'bag', ignore_errors=True)
    sim_time = args.clock == 'sim'
    parameters = NODE_PARAMETERS if sim_time else WALL_PARAMETERS
    processes = [NodeProcess('swivel_car_telemetry', 'recorder_node', domain_id, {
        'use_sim_time': sim_time, 'output': str(args.report / 'bag'),
        'discovery_period': 0.2}),
                 NodeProcess('swivel_car_telemetry', 'robot_description_node', domain_id,
                             {'use_sim_time': sim_time})]
    processes += [start_node(package, executable, domain_id, parameters[executable])
                  for package, executable in NODES]
    recorded = RECORDED if sim_time else tuple(t for t in RECORDED if t != '/clock')
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    node = DemoNode(context, sim_time)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    wall_start = time.monotonic()
    try:
        def check_alive() -> bool:
            for process in processes:
                if not process.running():
                    raise DemoError(f'{process.name} exited:\n{process.output()[-3000:]}')
            return False

        progress.show('start', 'the stack: sim, controller, odometry, planner, recorder')
        spin_until(executor, lambda: check_alive() or (
            node.spawn.service_is_ready() and node.climb.server_is_ready()
            and node.recording.odom and node.recorded(recorded)), 90.0,
            'the stack and the recorder to come up')

        # [s] the times shown count from here on the system clock; sim time counts from 0.
        t0 = 0.0 if sim_time else node.recording.truth[0][0]
        step = demo_step(args)
        obstacle = StepObstacle(name=step.name, height=step.height, depth=step.depth,
                                width=step.width, distance=step.distance, yaw=step.yaw,
                                friction=step.friction)
        spawned = node.spawn.call_async(SpawnObstacle.Request(obstacle=obstacle))
        spin_until(executor, spawned.done, 30.0, 'sim/spawn_obstacle')
        if not spawned.result().success:
            raise DemoError(f'spawning the step failed: {spawned.result().message}')

        start_x = node.recording.odom[-1][1]
        drive_to = args.step_distance - args.stop_before

        def travelled() -> float:
            return node.recording.odom[-1][1] - start_x
        while travelled() < drive_to:
            check_alive()
            node.drive(args.drive_speed)
            progress.show('drive', f'towards the step: {args.step_distance - travelled():.2f} m '
                                   f'to go, t = {node.recording.odom[-1][0] - t0:.1f} s')
            spin_until(executor, lambda n=len(node.recording.odom): len(
                node.recording.odom) > n + 4, 30.0, 'odometry while driving')
        stopped_at = len(node.recording.truth)
        while True:
            node.drive(0.0)
            spin_until(executor, lambda n=len(node.recording.truth): len(
                node.recording.truth) > n + 9, 30.0, 'ground truth while stopping')
            xs = [row[1] for row in node.recording.truth[-10:]]
            if len(node.recording.truth) - stopped_at > 50 and max(xs) - min(xs) < 1e-3:
                break

        # The planner climbs what the detector saw since the car stopped.
        stopped = node.recording.truth[-1][0]
        progress.show('detect', 'waiting for the step detector to see the step')
        spin_until(executor, lambda: check_alive() or (
            node.detections and node.detections[-1].found
            and stamp_to_seconds(node.detections[-1].header.stamp) >= stopped), 30.0,
            'a detection of the step after stopping')
        seen, frame = node.detections[-1], node.depth
        seen_truth_x = node.recording.truth[-1][1]  # [m] base_link's x in the world then
        goal = ClimbStep.Goal(use_detected_step=True, plan_only=False,
                              time_allowance=args.time_allowance)
        climb_start = node.recording.truth[-1][0]
        sent = node.climb.send_goal_async(goal, feedback_callback=lambda f: progress.show(
            f.feedback.phase_name, f'{100 * f.feedback.progress:3.0f} %  swivel '
            f'{f.feedback.swivel_angle:+.2f} rad  pitch {f.feedback.pitch:+.2f} rad  torque '
            f'{f.feedback.swivel_torque:+5.1f} N m, '
            f't = {node.recording.truth[-1][0] - t0:.1f} s'))
        spin_until(executor, lambda: check_alive() or sent.done(), 30.0, 'goal acceptance')
        if not sent.result().accepted:
            raise DemoError('the planner rejected the climb goal')
        result_future = sent.result().get_result_async()
        spin_until(executor, lambda: check_alive() or result_future.done(),
                   args.wall_timeout, 'the climb to end')
        result = result_future.result().result
        progress.done()
        climb_end = node.recording.truth[-1][0]
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
        codes = {process.name: process.stop() for process in processes}
        failed = {name: code for name, code in codes.items() if code not in (0, -2)}
        if failed:
            print(f'warning: nodes exited with {failed}', file=sys.stderr)
    recording = read_bag(args.report / 'bag')
    summary = summarise(args, recording, result, climb_start, climb_end,
                        time.monotonic() - wall_start)
    s = seen.step
    summary['detected'] = {'height': s.height, 'distance': s.distance, 'yaw': s.yaw,
                           'width': s.width, 'ends': (seen.left_end_seen, seen.right_end_seen),
                           'height_std': seen.height_std, 'distance_std': seen.distance_std,
                           'yaw_std': seen.yaw_std}
    # The car stands square to the step at the world's y = 0 (its heading drifts by less
    # than a milliradian while it drives straight).
    summary['truth_step'] = {'height': step.height, 'distance': step.distance - seen_truth_x,
                             'yaw': step.yaw, 'width': step.width}
    summary['depth_frame'] = frame
    return summary, recording


def summarise(args, recording: Recording, result, climb_start: float, climb_end: float,
              wall_time: float) -> dict:
    truth = np.array(recording.truth)
    odom = np.array(recording.odom)
    # Both start at the robot's initial pose: the sim spawns it at the world origin and the
    # odometry starts at zero.
    truth_xy_at_odom_end = np.array([np.interp(odom[-1, 0], truth[:, 0], truth[:, i])
                                     for i in (1, 2)])
    path = np.sum(np.hypot(np.diff(truth[:, 1]), np.diff(truth[:, 2])))
    odom_error = float(np.hypot(*(odom[-1, 1:] - truth_xy_at_odom_end)))
    return {
        'success': bool(result.success),
        'error_code': int(result.error_code),
        'message': result.message,
        'step_height': args.step_height,
        'climb_time': climb_end - climb_start,
        'sim_time': float(truth[-1, 0] - (0.0 if args.clock == 'sim' else truth[0, 0])),
        'wall_time': wall_time,
        'peak_torque': result.outcome.peak_torque,
        'energy': result.outcome.energy,
        'planned_peak_torque': result.plan.peak_torque,
        'planned_energy': result.plan.energy,
        'swivel_angle': result.plan.swivel_angle,
        'final_height': float(truth[-1, 3]),
        'path_length': float(path),
        'odometry_error': odom_error,
        'odometry_error_percent': 100.0 * odom_error / max(path, 1e-9),
        'climb_start': climb_start,
        'climb_end': climb_end,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--step-height', type=float, default=None,
                        help='[m] default: the highest step the whole car climbs reliably, '
                        "the planner's installed capability table")
    parser.add_argument('--step-distance', type=float, default=1.8,
                        help='[m] front axle ground contact to the step edge at the start')
    parser.add_argument('--stop-before', type=float, default=1.0,
                        help='[m] stop driving this far before the step, then climb')
    parser.add_argument('--drive-speed', type=float, default=0.3, help='[m/s]')
    parser.add_argument('--time-allowance', type=float, default=120.0, help='[s] sim time')
    parser.add_argument('--wall-timeout', type=float, default=900.0, help='[s]')
    parser.add_argument('--domain-id', type=int, default=60 + os.getpid() % 40)
    parser.add_argument('--report', type=Path, default=REPO_ROOT / 'report')
    parser.add_argument('--clock', choices=('sim', 'wall'), default='sim',
                        help='sim: on sim time in lockstep (deterministic); wall: as the robot '
                        'runs, the system clock, realistic sensors, no lockstep')
    args = parser.parse_args(argv)
    if args.step_height is None:
        table, _ = capability.table_for(capability.INSTALLED)
        args.step_height = table.limit

    progress = Progress()
    try:
        summary, recording = run_demo(args, progress)
    except (DemoError, TimeoutError) as error:
        progress.done()
        print(f'demo failed: {error}', file=sys.stderr)
        return 2
    print_summary(summary)
    page = write_report(summary, recording, demo_step(args), args.report)
    append_detection(page, summary)
    print(f'  report               {page}')
    return 0 if summary['success'] else 1


def print_summary(summary: dict) -> None:
    print(f"\nclimb {'SUCCEEDED' if summary['success'] else 'FAILED'}: {summary['message']}")
    print(f"  step height          {summary['step_height']:.3f} m")
    print(f"  climb time           {summary['climb_time']:.1f} s sim "
          f"(whole demo {summary['sim_time']:.1f} s sim, {summary['wall_time']:.1f} s wall)")
    print(f"  peak swivel torque   {summary['peak_torque']:.2f} N m "
          f"(planned {summary['planned_peak_torque']:.2f})")
    print(f"  swivel energy        {summary['energy']:.2f} J "
          f"(planned {summary['planned_energy']:.2f})")
    print(f"  odometry error       {summary['odometry_error']:.3f} m over "
          f"{summary['path_length']:.2f} m ({summary['odometry_error_percent']:.1f} %)")
    for name, scale, unit in DETECTION_ROWS:
        seen, truth = summary['detected'][name], summary['truth_step'][name]
        print(f'  detected {name:<12}{seen * scale:7.1f} {unit} (truth {truth * scale:.1f} '
              f'{unit})')


DETECTION_ROWS = (('height', 100.0, 'cm'), ('distance', 100.0, 'cm'), ('yaw', 1.0, 'rad'),
                  ('width', 100.0, 'cm'))


def append_detection(page: Path, summary: dict) -> None:
    """Add what the car saw to the report: its depth image, the detection beside the truth."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    lines = ['', '## What the car saw', '',
             'The climb was `climb_step {use_detected_step: true}`: the planner was not told '
             "where the step is. The step detector measured it in the depth camera's images "
             '(a RealSense D435-class camera on the body, rendered by the sim with its noise); '
             'the planner took its latest detection after the car stopped.', '']
    frame = summary['depth_frame']
    if frame is not None:
        depth = np.frombuffer(bytes(frame.data), dtype='<f4').reshape(frame.height, frame.width)
        figure, axes = plt.subplots(figsize=(6.4, 3.8))
        shown = axes.imshow(depth, cmap='viridis', vmin=0.0, vmax=3.0)
        figure.colorbar(shown, ax=axes, label='depth [m] (white: no return)')
        axes.set_title('depth image (32FC1) when the climb was asked')
        axes.set_axis_off()
        figure.savefig(page.parent / 'depth.png', dpi=100, bbox_inches='tight')
        plt.close(figure)
        lines += ['![the depth image the detector saw](depth.png)', '']
    detected, truth = summary['detected'], summary['truth_step']
    lines += ['| | detected (one sigma) | truth |', '|---|---|---|']
    sigmas = {'height': detected['height_std'], 'distance': detected['distance_std'],
              'yaw': detected['yaw_std']}
    for name, scale, unit in DETECTION_ROWS:
        sigma = f' (+-{sigmas[name] * scale:.2g})' if name in sigmas else ''
        lines.append(f'| {name} | {detected[name] * scale:.2f}{sigma} {unit} | '
                     f'{truth[name] * scale:.2f} {unit} |')
    left, right = detected['ends']
    lines += ['', f'Ends of the edge seen: left {left}, right {right} (the width is measured '
                  'only between seen ends; otherwise it is what was in view).', '']
    with page.open('a') as out:
        out.write('\n'.join(lines))


if __name__ == '__main__':
    sys.exit(main())
