"""The in-process stack (swivel_car_bringup.inprocess) is the ROS lockstep run: one climb
through the installed executables and through InProcessStack gives the same outcome and the
same ground truth in every control period, bit for bit.

Why bit for bit can be asked: in lockstep every node acts on the state of one moment, the
planner's command takes effect exactly one period later, and the in-process stack calls the
same cores, through the same ROS-free conversions, on the same floats (stamps as
``sec + nanosec * 1e-9`` of whole physics steps; the odometry heading through its message's
quaternion; float64 message fields carry floats unchanged). pybullet is deterministic for the
same sequence of calls. What is not determined by the lockstep is when a climb starts and the
planner's very first command: the controller waits for the planner only while it holds a
command, so the first one could race the next state. The test therefore pauses the sim,
asks for the climb, steps the one period the climb's first tick needs (sim/step), waits until
the controller has taken the first command, and only then lets the sim run; the in-process
stack settles to that tick's time and climbs from it.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from swivel_car_msgs.msg import ActuatorCommand, SwivelCommand
from swivel_car_msgs.srv import ClimbStep, StepSimulation

from swivel_car_bringup.inprocess import InProcessStack
from swivel_car_planner.core import ClimbRequest, ErrorCode
from swivel_car_planner.sim_session import SimSession

HEIGHT = 0.04  # [m]
DISTANCE = 1.0  # [m] front axle to the edge; nearer, the planner has no room to align
SETTLE = 0.2  # [s] of sim time before the climb is asked
QUIET = 0.3  # [s] wall: messages of the paused moment delivered (localhost takes < 1 ms)


def _seconds(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9  # as every node converts stamps


class _Recorder:
    """Ground truth, joint positions and actuator commands of the ROS run, by stamp."""

    def __init__(self, session: SimSession) -> None:
        node = session.node
        self.truth: dict[float, Odometry] = {}
        self.joints: dict[float, JointState] = {}
        self.commands: dict[float, ActuatorCommand] = {}
        self.swivel_commands: list[SwivelCommand] = []
        node.create_subscription(Odometry, 'ground_truth/odom', self._keep(self.truth), 5000)
        node.create_subscription(JointState, 'joint_states', self._keep(self.joints), 5000)
        node.create_subscription(ActuatorCommand, 'actuator_command',
                                 self._keep(self.commands), 5000)
        node.create_subscription(SwivelCommand, 'swivel_command', self.swivel_commands.append,
                                 5000)

    @staticmethod
    def _keep(by_stamp: dict):
        def callback(msg) -> None:
            by_stamp[_seconds(msg.header.stamp)] = msg
        return callback

    def rows(self, times: np.ndarray) -> dict[str, np.ndarray]:
        missing = [t for t in times if t not in self.truth or t not in self.joints
                   or t not in self.commands]
        assert not missing, f'{len(missing)} control periods not recorded, first {missing[0]}'
        truth = [self.truth[t].pose.pose for t in times]
        return {
            'position': np.array([(p.position.x, p.position.y, p.position.z) for p in truth]),
            'orientation': np.array([(p.orientation.x, p.orientation.y, p.orientation.z,
                                      p.orientation.w) for p in truth]),
            'joint_positions': np.array([list(self.joints[t].position) for t in times]),
            'swivel_torque': np.array([self.commands[t].swivel_torque for t in times]),
            'drive_speed': np.array([self.commands[t].drive_speed for t in times]),
        }


def _ros_climb(session: SimSession, recorder: _Recorder, request: ClimbStep.Request):
    """The climb through the executables, its first tick at a known state; returns the
    response and that tick's time [s]."""
    step_client = session.node.create_client(StepSimulation, 'sim/step')
    controller, planner = session.processes[1], session.processes[3]
    node = session.node

    def graph_complete() -> bool:
        return (node.count_subscribers('joint_states') >= 4  # controller, odometry, planner
                and node.count_subscribers('imu') >= 1
                and node.count_subscribers('odom') >= 2
                and node.count_subscribers('controller/controller_state') >= 2
                and node.count_subscribers('swivel_command') >= 2
                and node.count_subscribers('actuator_command') >= 2
                and node.count_subscribers('/clock') >= 3
                and all(c.service_is_ready() for c in (
                    session.spawn_client, session.pause_client, session.climb_client,
                    step_client)))

    session.spin_until(graph_complete, 60.0, 'every node and service')
    _spin_for(session, QUIET)  # the endpoints match
    # Paused at sim time 0: the world as the in-process stack builds it.
    session.spawn_step(HEIGHT, DISTANCE)
    session.set_paused(False)  # the sim republishes the state of 0 s; the chain runs
    session.spin_until(lambda: session.time >= SETTLE, 60.0, 'sim time to pass')
    # Until the planner hears the stack (a step out of reach is refused as unreachable).
    deadline = time.monotonic() + 60.0
    while session.climb(10.0, 1.0).error_code == ClimbStep.Response.ERROR_NOT_READY:
        assert time.monotonic() < deadline, 'the planner never got ready'
        session.settle(0.1)
    session.set_paused(True)
    _spin_for(session, QUIET)

    response = session.climb_client.call_async(request)
    session.spin_until(lambda: 'climbing a' in planner.output() or response.done(), 60.0,
                       'the planner to accept the climb')
    assert not response.done(), (response.result().message, planner.output()[-3000:])
    _spin_for(session, QUIET)
    if not recorder.swivel_commands:  # the usual case: its first tick is the next state
        stepped = step_client.call_async(StepSimulation.Request(steps=5))
        session.spin_until(stepped.done, 30.0, 'sim/step')
        assert stepped.result().success, stepped.result().message
    session.spin_until(lambda: recorder.swivel_commands, 30.0, 'the first swivel_command')
    first_tick = _seconds(recorder.swivel_commands[0].header.stamp)
    session.spin_until(lambda: 'swivel_command takes over' in controller.output(), 30.0,
                       'the controller to take the first command')
    session.set_paused(False)
    session.spin_until(response.done, 300.0, 'the climb')
    return response.result(), first_tick


def _spin_for(session: SimSession, seconds: float) -> None:
    end = time.monotonic() + seconds
    session.spin_until(lambda: time.monotonic() > end, seconds + 10.0, 'a moment')


@pytest.fixture(scope='module')
def ros_run():
    # Paced at real time (SimSession's lockstep): faster, the sim runs away from the planner
    # before the climb, and the planner would take the climb's first ticks from a backlog.
    session = SimSession(sim_parameters={'start_paused': True})
    try:
        recorder = _Recorder(session)
        result, first_tick = _ros_climb(session, recorder, ClimbStep.Request(
            step_height=HEIGHT, step_distance=DISTANCE, step_yaw=0.0, plan_only=False))
        logs = {process.name: process.output() for process in session.processes}
        yield result, first_tick, recorder, logs
    finally:
        crashed = session.close()
    assert not crashed, crashed


def test_a_ros_lockstep_climb_is_the_in_process_climb(ros_run):
    ros, first_tick, recorder, logs = ros_run
    # The chain must have held: no node went on without the command it waits for.
    late = [line for text in logs.values() for line in text.splitlines()
            if 'lockstep_wait' in line or 'lockstep: no actuator_command' in line]
    assert not late, late
    assert ros.success, f'{ros.error_code}: {ros.message}'

    with InProcessStack() as stack:
        stack.spawn_step(HEIGHT, DISTANCE)
        stack.settle(first_tick)
        assert stack.time == first_tick
        ours = stack.climb(ClimbRequest(HEIGHT, DISTANCE, 0.0))
        assert stack.four_wheels_on_top(HEIGHT)

    trajectory = ours.trajectory
    theirs = recorder.rows(trajectory.time)
    differences = {name: float(np.max(np.abs(getattr(trajectory, name) - values)))
                   for name, values in theirs.items()}
    # Bit-identical: any difference would mean the two runs' inputs differ somewhere.
    assert all(value == 0.0 for value in differences.values()), differences
    assert ours.start_time == first_tick
    assert (ours.success, int(ours.error_code), ours.message) == (
        ros.success, ros.error_code, ros.message)
    assert ours.error_code == ErrorCode.NONE
    for name in ('duration', 'peak_torque', 'energy', 'max_pitch', 'distance_travelled'):
        assert getattr(ours.outcome, name) == getattr(ros.outcome, name), name
    assert ours.plan.swivel_angle == ros.plan.swivel_angle

    assert len(trajectory) == round(ours.outcome.duration / stack.control_period) + 1
