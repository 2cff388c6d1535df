"""
The in-process stack (swivel_car_studies.inprocess) is the ROS lockstep run, bit for bit.

One climb through the installed executables and through InProcessStack gives the same outcome
and the same ground truth, joint positions and actuator commands in every control period.

Why bit for bit can be asked: in lockstep every node acts on the state of one moment, the
planner's command takes effect exactly one period later, and the in-process stack calls the
same cores, through the same ROS-free conversions, on the same floats (stamps as
``sec + nanosec * 1e-9`` of whole physics steps; the odometry heading through its message's
quaternion; float64 message fields carry floats unchanged). pybullet is deterministic for the
same sequence of calls. What the lockstep does not determine:

- when the climb starts, and the planner's very first command: the controller waits for the
  planner only while it holds a command, so the first one could race the next state. The test
  pauses the sim, asks for the climb, steps the one period the climb's first tick needs
  (sim/step), waits until the controller has taken the first command, and only then lets the
  sim run (sim/run, 50 control periods at a time, the recorder catching up after each); the
  in-process stack settles to that tick's time and climbs from it;
- the odometry before the climb: outside the chain nothing waits for it, so it may start
  after the sim's first states or, under load, fall more than its queue behind the unpaced sim
  and integrate fewer, longer steps (most of them, under load; without the reset the runs
  differ from about 1 s into the climb, drive_speed by 1e-15 rad/s). Both runs reset it to
  the origin at the paused moment, once it has integrated that state.
"""

from __future__ import annotations

import time

from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rclpy.serialization import deserialize_message
from sensor_msgs.msg import JointState
from sim_session import SimSession
from std_srvs.srv import Empty
from swivel_car_msgs.msg import ActuatorCommand, SwivelCommand
from swivel_car_msgs.srv import ClimbStep, StepSimulation
from swivel_car_planner.core import ClimbRequest, ErrorCode
from swivel_car_ros.serialized import read_header
from swivel_car_sim.config import SimNodeConfig
from swivel_car_sim.sim_node import LOCKSTEP_TIMED_OUT_LOG
from swivel_car_studies.inprocess import InProcessStack, StackConfig

HEIGHT = 0.04  # [m]
DISTANCE = 1.0  # [m] front axle to the edge; nearer, the planner has no room to align
# Share of the climb's control periods the recorder must have in every stream.
MIN_RECORDED = 0.9  # [1]
# Physics steps the ROS climb runs at a time (sim/run), the recorder catching up after each:
# 50 control periods, half of what the sim's writers keep for a reader that trails them.
RUN_STEPS = 250  # [1]


def _seconds(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9  # as every node converts stamps


class _Recorder:
    """
    Ground truth, joint positions, actuator commands and odometry of the ROS run, by stamp.

    Kept serialized, read when compared: deserializing on receipt, this node, outside the
    chain, trails a loaded, unpaced sim by more than the sim's writers keep (100 messages) and
    loses states.
    """

    def __init__(self, session: SimSession) -> None:
        node = session.node
        self.truth: dict[float, bytes] = {}
        self.joints: dict[float, bytes] = {}
        self.commands: dict[float, bytes] = {}
        self.odometry: dict[float, bytes] = {}
        self.swivel_commands: list[bytes] = []
        self.heard = 0  # messages recorded
        for msg_type, topic, by_stamp in ((Odometry, 'ground_truth/odom', self.truth),
                                          (JointState, 'joint_states', self.joints),
                                          (ActuatorCommand, 'actuator_command', self.commands),
                                          (Odometry, 'odom', self.odometry)):
            node.create_subscription(msg_type, topic, self._keep(by_stamp), 5000, raw=True)
        node.create_subscription(SwivelCommand, 'swivel_command', self.swivel_commands.append,
                                 5000, raw=True)

    def _keep(self, by_stamp: dict):
        def callback(data: bytes) -> None:
            by_stamp[_seconds(read_header(data)[0])] = data
            self.heard += 1
        return callback

    def first_swivel_command(self) -> SwivelCommand:
        return deserialize_message(self.swivel_commands[0], SwivelCommand)

    def heard_until(self, end: float) -> bool:
        """Every recorded stream has reached the stamp ``end`` [s] (each comes in order)."""
        return all(stream and next(reversed(stream)) >= end
                   for stream in (self.truth, self.joints, self.commands, self.odometry))

    def rows(self, times: np.ndarray) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """
        Return which of ``times`` [s] were recorded in every stream, and their values.

        The sim's writers keep 100 messages each: this node, outside the chain, can still
        lose a few on a loaded machine even reading them serialized. The periods it has are
        compared bit for bit; it must have at least ``MIN_RECORDED`` of them, the first and
        the last among them.
        """
        streams = (self.truth, self.joints, self.commands)
        recorded = np.array([all(t in stream for stream in streams) for t in times])
        missing = times[~recorded]
        assert recorded.mean() >= MIN_RECORDED and recorded[0] and recorded[-1], (
            f'{len(missing)} of {len(times)} control periods not recorded in every stream: '
            f'{missing[:3]}...{missing[-3:]}')
        kept = times[recorded]
        truth = [deserialize_message(self.truth[t], Odometry).pose.pose for t in kept]
        joints = [deserialize_message(self.joints[t], JointState) for t in kept]
        commands = [deserialize_message(self.commands[t], ActuatorCommand) for t in kept]
        return recorded, {
            'position': np.array([(p.position.x, p.position.y, p.position.z) for p in truth]),
            'orientation': np.array([(p.orientation.x, p.orientation.y, p.orientation.z,
                                      p.orientation.w) for p in truth]),
            'joint_positions': np.array([list(j.position) for j in joints]),
            'swivel_torque': np.array([c.swivel_torque for c in commands]),
            'drive_speed': np.array([c.drive_speed for c in commands]),
        }


def _ros_climb(session: SimSession, recorder: _Recorder, request: ClimbStep.Request,
               sim: SimNodeConfig):
    """
    Climb through the executables, the climb's first tick at a known state.

    Returns the response and that tick's time [s].
    """
    step_client = session.node.create_client(StepSimulation, 'sim/step')
    controller, planner = session.processes[1], session.processes[3]
    session.spin_until(lambda: all(client.service_is_ready() for client in (
        session.spawn_client, session.pause_client, step_client)), 60.0, 'the sim')
    # The planner starts last and slowest: the sim runs once it can answer.
    session.spin_until(lambda: 'planner ready' in planner.output(), 60.0, 'the planner')
    # Paused at sim time 0: the world as the in-process stack builds it.
    session.spawn_step(HEIGHT, DISTANCE)
    session.set_paused(False)
    session.wait_ready()  # until the planner hears the stack
    # Paused by sim/run, in lockstep: it names the state it holds, however late this node
    # hears the states before it, and the controller has answered that state (sim/step would
    # step on at once, with the answer to the state before if this one's was still on its
    # way).
    paused = _seconds(session.run(sim.steps_per_period))  # [s] the state the sim stopped at
    # Outside the chain the odometry may trail the sim: reset it once it has that state.
    session.spin_until(lambda: paused in recorder.commands and paused in recorder.odometry,
                       30.0, 'the controller and odometry to answer the paused state')
    session.call(session.odometry_reset, Empty.Request())

    response = session.climb_client.call_async(request)
    session.spin_until(lambda: 'climbing a' in planner.output() or response.done(), 60.0,
                       'the planner to accept the climb')
    assert not response.done(), (response.result().message, planner.output()[-3000:])
    stepped = step_client.call_async(StepSimulation.Request(steps=sim.steps_per_period))
    session.spin_until(stepped.done, 30.0, 'sim/step')
    assert stepped.result().success, stepped.result().message
    first_tick = _seconds(stepped.result().sim_time)
    session.spin_until(lambda: recorder.swivel_commands, 30.0, 'the first swivel_command')
    assert _seconds(recorder.first_swivel_command().header.stamp) == first_tick, \
        'the planner ticked on inputs from before the climb'
    session.spin_until(lambda: 'swivel_command takes over' in controller.output(), 30.0,
                       'the controller to take the first command')
    # Run freely, the climb outran this node, outside the chain, by more than the writers
    # keep: it lost 242 of 1036 periods once the chain had become faster.
    deadline = time.monotonic() + 300.0  # [s] wall, a guard against a hung stack
    while not response.done():
        assert time.monotonic() < deadline, 'the climb did not end within 300 s'
        run_end = _seconds(session.run(RUN_STEPS))  # [s]
        session.spin_until(lambda: recorder.heard_until(run_end), 30.0,
                           'the recorded messages of the run')
    result = response.result()
    end = first_tick + result.outcome.duration - 0.5 * sim.control_period  # [s]
    session.spin_until(lambda: recorder.heard_until(end), 30.0, 'the recorded messages')
    return result, first_tick


@pytest.fixture
def ros_run():
    session = SimSession()  # paused at sim time 0 until _ros_climb resumes it
    try:
        recorder = _Recorder(session)
        result, first_tick = _ros_climb(session, recorder, ClimbStep.Request(
            step_height=HEIGHT, step_distance=DISTANCE, step_yaw=0.0, plan_only=False),
            StackConfig.installed().sim)
        logs = {process.name: process.output() for process in session.processes}
    finally:
        crashed = session.close()  # before the in-process run: it would compete for the CPU
    assert not crashed, crashed
    return result, first_tick, recorder, logs


def test_a_ros_lockstep_climb_is_the_in_process_climb(ros_run):
    ros, first_tick, recorder, logs = ros_run
    # The chain must have held: no node went on without the command it waits for.
    late = [line for text in logs.values() for line in text.splitlines()
            if 'lockstep_wait' in line or LOCKSTEP_TIMED_OUT_LOG in line]
    assert not late, late
    assert ros.success, f'{ros.error_code}: {ros.message}'

    with InProcessStack() as stack:
        stack.spawn_step(HEIGHT, DISTANCE)
        stack.settle(first_tick)
        assert stack.time == first_tick
        stack.reset_odometry()
        ours = stack.climb(ClimbRequest(HEIGHT, DISTANCE, 0.0))
        assert stack.four_wheels_on_top(HEIGHT)

    trajectory = ours.trajectory
    differing = {}  # quantity -> (first period that differs [s], largest difference)
    recorded, ros_rows = recorder.rows(trajectory.time)
    times = trajectory.time[recorded]
    for name, values in ros_rows.items():
        ours_values = np.asarray(getattr(trajectory, name))[recorded]
        difference = np.abs(ours_values - values).reshape(len(values), -1)
        rows = np.flatnonzero(np.any(difference != 0.0, axis=1))
        if len(rows):
            differing[name] = (float(times[rows[0]]), float(np.max(difference)))
    # Bit-identical: any difference would mean the two runs' inputs differ somewhere.
    assert not differing, (f'the climb from {first_tick} s', differing)
    assert ours.start_time == first_tick
    assert (ours.success, int(ours.error_code), ours.message) == (
        ros.success, ros.error_code, ros.message)
    assert ours.error_code == ErrorCode.NONE
    for name in ('duration', 'peak_torque', 'energy', 'max_pitch', 'distance_travelled'):
        assert getattr(ours.outcome, name) == getattr(ros.outcome, name), name
    assert ours.plan.swivel_angle == ros.plan.swivel_angle

    assert len(trajectory) == round(ours.outcome.duration / stack.control_period) + 1
