"""The sim node's ROS surface, in process with real rclpy: lockstep, services, bad requests."""

import math
import os
import time

from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
import pytest
import rclpy
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState
from std_msgs.msg import Header
from std_srvs.srv import SetBool
from swivel_car_msgs.msg import ActuatorCommand, StepObstacle
from swivel_car_msgs.srv import RemoveObstacle, ResetSimulation, SpawnObstacle, StepSimulation
from swivel_car_sim.sim_node import (LOCKSTEP_RESUMED_LOG, LOCKSTEP_TIMED_OUT_LOG,
                                     PACE_TIMED_OUT_LOG, SimNode)
from swivel_car_testing import next_domain_id, spin_until

TIMEOUT = 20.0  # [s] wall guard against a hang, not a measurement


def _ns(stamp) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


class Harness:
    """
    A SimNode and a client node on one executor, in a fresh ROS domain and their own namespace.

    The namespace because other test runs on this machine may share the domain.
    """

    count = 0

    def __init__(self, **parameters) -> None:
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
        Harness.count += 1
        namespace = f'/sim_node_test_{os.getpid()}_{Harness.count}'
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=next_domain_id())
        self.sim = SimNode(context=self.context, namespace=namespace, parameter_overrides=[
            Parameter(name, value=value) for name, value in parameters.items()])
        self.client = Node('test_client', namespace=namespace, context=self.context)
        self.executor = EventsExecutor(context=self.context)
        self.executor.add_node(self.sim)
        self.executor.add_node(self.client)
        self.joint_states, self.clock, self.imu, self.odom = [], [], [], []
        self.client.create_subscription(JointState, 'joint_states', self.joint_states.append, 50)
        self.client.create_subscription(Clock, '/clock', self.clock.append, 50)
        self.client.create_subscription(Imu, 'imu', self.imu.append, 50)
        self.client.create_subscription(Odometry, 'ground_truth/odom', self.odom.append, 50)
        self.commands = self.client.create_publisher(ActuatorCommand, 'actuator_command', 10)

    def call(self, kind, name: str, request):
        client = self.client.create_client(kind, f'sim/{name}')
        spin_until(self.executor, client.service_is_ready, TIMEOUT, f'service {name}')
        future = client.call_async(request)
        spin_until(self.executor, future.done, TIMEOUT, f'{name} response')
        return future.result()

    def command(self, stamp, swivel_torque: float = 0.0, drive_speed: float = 0.0) -> None:
        msg = ActuatorCommand(swivel_torque=swivel_torque, drive_speed=drive_speed)
        msg.header.stamp = stamp
        self.commands.publish(msg)

    def close(self) -> None:
        self.executor.shutdown()
        self.sim.destroy_node()
        self.client.destroy_node()
        rclpy.try_shutdown(context=self.context)


@pytest.fixture
def harness_factory():
    made = []

    def make(**parameters):
        made.append(Harness(**parameters))
        return made[-1]
    yield make
    for h in made:
        h.close()


def test_lockstep_advances_one_period_per_matching_command(harness_factory):
    h = harness_factory(lockstep=True, lockstep_timeout=0.0)
    spin_until(h.executor, lambda: h.joint_states, TIMEOUT, 'first joint_states')
    answered = set()
    while len(answered) < 50:
        latest = h.joint_states[-1]
        if _ns(latest.header.stamp) not in answered:
            answered.add(_ns(latest.header.stamp))
            h.command(latest.header.stamp, drive_speed=5.0)
        count = len(h.joint_states)
        spin_until(h.executor, lambda: len(h.joint_states) > count, TIMEOUT, 'next state')
    stamps = sorted({_ns(m.header.stamp) for m in h.joint_states})
    assert stamps == [i * 10_000_000 for i in range(len(stamps))]
    assert stamps[-1] == 50 * 10_000_000
    assert h.sim.sim.steps == 50 * 5
    assert h.joint_states[-1].name == ['swivel_joint', 'rear_left_wheel_joint',
                                       'rear_right_wheel_joint', 'front_left_wheel_joint',
                                       'front_right_wheel_joint']
    assert h.joint_states[-1].velocity[1] > 1.0  # the commanded drive acts
    spin_until(h.executor, lambda: h.odom and _ns(h.odom[-1].header.stamp) == stamps[-1],
               TIMEOUT, 'ground truth')
    assert h.odom[-1].header.frame_id == 'world'
    assert h.odom[-1].child_frame_id == 'base_link'
    assert h.odom[-1].twist.twist.linear.x > 0.05
    assert stamps[-1] in {_ns(m.clock) for m in h.clock}  # /clock is global: others may add
    assert h.imu[-1].linear_acceleration.z == pytest.approx(9.81, abs=0.3)
    assert h.imu[-1].header.frame_id == 'base_link'
    assert h.imu[-1].orientation.w == pytest.approx(1.0, abs=1e-3)


def test_clock_rate_publishes_every_nth_state_time_on_clock(harness_factory):
    h = harness_factory(lockstep=True, lockstep_timeout=0.0, clock_rate=10.0)
    spin_until(h.executor, lambda: h.joint_states, TIMEOUT, 'first joint_states')
    while _ns(h.joint_states[-1].header.stamp) < 250_000_000:
        count = len(h.joint_states)
        h.command(h.joint_states[-1].header.stamp)
        spin_until(h.executor, lambda: len(h.joint_states) > count, TIMEOUT, 'next state')
    spin_until(h.executor, lambda: h.clock and _ns(h.clock[-1].clock) == 200_000_000, TIMEOUT,
               '/clock of 0.2 s')
    states = {_ns(m.header.stamp) for m in h.joint_states}
    assert states >= set(range(0, 250_000_001, 10_000_000))
    assert {_ns(m.clock) for m in h.clock} & states == {0, 100_000_000, 200_000_000}


def test_lockstep_ignores_stale_stamps_and_non_finite_commands(harness_factory):
    h = harness_factory(lockstep=True, lockstep_timeout=0.0)
    spin_until(h.executor, lambda: h.joint_states, TIMEOUT, 'first joint_states')
    stale = h.joint_states[-1].header.stamp
    h.command(stale)
    spin_until(h.executor, lambda: h.sim.sim.steps == 5, TIMEOUT, 'one period')
    h.command(stale)  # the stamp of a state already answered
    h.command(h.sim._stamp(), math.nan)
    for _ in range(20):
        h.executor.spin_once(timeout_sec=0.01)
    assert h.sim.sim.steps == 5


def test_lockstep_pace_cap_holds_sim_time_below_wall_time(harness_factory):
    # A lower bound only: the sim may never run ahead of the cap, however fast the answers.
    h = harness_factory(lockstep=True, lockstep_timeout=0.0, lockstep_real_time_factor=2.0)
    spin_until(h.executor, lambda: h.joint_states, TIMEOUT, 'first joint_states')
    start = time.monotonic()
    answered = set()
    while h.sim.sim.steps < 20 * 5:
        latest = h.joint_states[-1]
        if _ns(latest.header.stamp) not in answered:
            answered.add(_ns(latest.header.stamp))
            h.command(latest.header.stamp)
        h.executor.spin_once(timeout_sec=0.001)
    assert time.monotonic() - start >= 20 * 0.01 / 2.0 * 0.95


def _lockstep_run(h: Harness, periods: int) -> JointState:
    """Answer each new state with a command that depends on it, as a controller would."""
    _answer_every_state(h, periods)
    spin_until(h.executor, lambda: _ns(h.joint_states[-1].header.stamp) == periods * 10**7,
               TIMEOUT, 'last state')
    return h.joint_states[-1]


def test_lockstep_results_do_not_depend_on_timing(harness_factory):
    first = _lockstep_run(harness_factory(lockstep=True, lockstep_timeout=0.0), 60)
    second = _lockstep_run(harness_factory(lockstep=True, lockstep_timeout=0.0), 60)
    assert first.position[0] > 0.03  # the swivel moved
    assert list(first.position) == list(second.position)
    assert list(first.velocity) == list(second.velocity)


def test_real_time_free_running_advances_and_applies_commands(harness_factory):
    h = harness_factory(real_time_factor=4.0)
    spin_until(h.executor, lambda: h.joint_states, TIMEOUT, 'first joint_states')
    h.command(h.joint_states[-1].header.stamp, drive_speed=5.0)
    spin_until(h.executor, lambda: h.sim.sim.time > 0.2, TIMEOUT, 'free running')
    assert h.joint_states[-1].velocity[1] > 1.0


def test_free_running_drops_a_command_computed_longer_ago_than_max_command_age(
        harness_factory):
    # Paused and stepped by hand: free running (no lockstep), but deterministic.
    h = harness_factory(real_time_factor=0.0, start_paused=True, max_command_age=0.01)
    assert h.call(StepSimulation, 'step', StepSimulation.Request(steps=300)).success  # 0.6 s
    h.command(Time(sec=0, nanosec=580_000_000), drive_speed=5.0)  # 0.02 s old
    spin_until(h.executor, lambda: h.sim.sim.time > 0.0 and h.joint_states, TIMEOUT, 'states')
    for _ in range(20):
        h.executor.spin_once(timeout_sec=0.01)
    step = StepSimulation.Request(steps=100)
    assert h.call(StepSimulation, 'step', step).success
    assert abs(h.sim.sim.state().velocities[1]) < 0.1
    h.command(Time(sec=0, nanosec=800_000_000), drive_speed=5.0)  # the state's own: applied
    for _ in range(20):
        h.executor.spin_once(timeout_sec=0.01)
    assert h.call(StepSimulation, 'step', step).success
    assert h.sim.sim.state().velocities[1] > 1.0


# The test controller's swivel torque names the state it answers (1 mN m per period of its
# stamp, at most 0.1 N m here: a nudge beside the 5-10 N m that hold the swivel), and each
# joint_states reports the torque applied (effort): so the age of the command the sim applied
# over every period is read from what the sim publishes.
STAMP_TORQUE = 1e-3  # [N m] per control period


def _answer_naming_the_stamp(h: Harness, until_ns: int) -> list[tuple[int, int]]:
    """
    Answer every new state as a controller would, until sim time ``until_ns`` [ns].

    Returns (stamp, stamp of the command applied in the period before it) [ns] of each state.
    """
    applied, seen, answered = [], 0, 10_000_000
    deadline = time.monotonic() + TIMEOUT
    while not applied or applied[-1][0] < until_ns:
        assert time.monotonic() < deadline, f'stalled at {applied[-1:]}'
        h.executor.spin_once(timeout_sec=0.05)
        for msg in h.joint_states[seen:]:
            stamp = _ns(msg.header.stamp)
            if msg.effort[0] != 0.0:  # 0: before the first command
                applied.append((stamp, round(msg.effort[0] / STAMP_TORQUE) * 10_000_000))
            if stamp > answered:
                answered = stamp
                h.command(msg.header.stamp, swivel_torque=stamp / 10_000_000 * STAMP_TORQUE,
                          drive_speed=3.0)
        seen = len(h.joint_states)
    return applied


def _answer_a_stamped_state_and_resume(h: Harness) -> None:
    """Step one period (a command stamped 0 counts as unstamped), answer it, resume."""
    assert h.call(StepSimulation, 'step', StepSimulation.Request(steps=5)).success
    spin_until(h.executor, lambda: h.joint_states and _ns(h.joint_states[-1].header.stamp),
               TIMEOUT, 'the stepped state')
    h.command(h.joint_states[-1].header.stamp, swivel_torque=STAMP_TORQUE, drive_speed=3.0)
    spin_until(h.executor, lambda: h.sim._pace.newest_ns, TIMEOUT, 'the command heard')
    assert h.call(SetBool, 'set_paused', SetBool.Request(data=False)).success


@pytest.mark.parametrize('real_time_factor,max_command_age', [
    (0.0, 0.0), (0.0, 0.01), (20.0, 0.0)])
def test_free_running_never_runs_ahead_of_its_controller(
        harness_factory, real_time_factor, max_command_age):
    # Issue 32: as fast as possible the sim ran 20x ahead of the controller and applied
    # commands computed up to watchdog_timeout (0.5 s) of sim time before: the swivel loop
    # closed over that delay and the car yawed back and forth at 3.5 rad/s. A protocol bound:
    # the sim steps on from the state of t only with a command answering t - max_command_age
    # or later, so over any period the command applied is at most one period older than that.
    h = harness_factory(real_time_factor=real_time_factor, start_paused=True,
                        lockstep_timeout=0.0, max_command_age=max_command_age)
    _answer_a_stamped_state_and_resume(h)
    applied = _answer_naming_the_stamp(h, 1_000_000_000)
    ages = [stamp - command for stamp, command in applied]  # [ns]
    assert max(ages) <= round(max_command_age * 1e9) + 10_000_000, applied
    assert len(applied) >= 99, applied  # it ran, and no state was lost to the queue
    assert min(ages) >= 10_000_000  # no command applied before the state it answers


def test_free_running_without_its_controller_waits_lockstep_timeout_then_runs_on(
        harness_factory, capfd):
    h = harness_factory(real_time_factor=0.0, start_paused=True, lockstep_timeout=0.2)
    _answer_a_stamped_state_and_resume(h)
    # Then no answer: the sim waits (a wall-time wait, so only its end is checked: it comes,
    # and the watchdog has stopped the car once the sim ran on without the controller).
    spin_until(h.executor, lambda: h.sim.sim.time > 1.0, TIMEOUT, 'running on')
    assert h.sim.sim.watchdog_tripped
    assert f'{PACE_TIMED_OUT_LOG} for 0.2 s' in capfd.readouterr().err


def test_step_service_advances_lockstep_without_a_controller(harness_factory):
    h = harness_factory(lockstep=True, lockstep_timeout=0.0)
    response = h.call(StepSimulation, 'step', StepSimulation.Request(steps=23))
    assert response.success, response.message
    assert _ns(response.sim_time) == 23 * 2_000_000
    # states at the two crossed control periods, then (republished while waiting for a
    # command) the state at the end of the step
    wanted = {10_000_000, 20_000_000, 46_000_000}
    spin_until(h.executor, lambda: {_ns(m.header.stamp) for m in h.joint_states} >= wanted,
               TIMEOUT, 'states at the crossed control periods')


def test_pause_stops_free_running_and_step_moves_it(harness_factory):
    h = harness_factory(real_time_factor=0.0, start_paused=True)
    for _ in range(20):
        h.executor.spin_once(timeout_sec=0.01)
    assert h.sim.sim.steps == 0
    assert h.call(StepSimulation, 'step', StepSimulation.Request(steps=7)).success
    assert h.sim.sim.steps == 7
    assert h.call(SetBool, 'set_paused', SetBool.Request(data=False)).success
    spin_until(h.executor, lambda: h.sim.sim.steps > 1000, TIMEOUT, 'free running')
    refused = h.call(StepSimulation, 'step', StepSimulation.Request(steps=7))
    assert not refused.success and 'pause' in refused.message


def test_run_advances_whole_periods_and_pauses_at_the_state_they_end_in(harness_factory):
    h = harness_factory(real_time_factor=0.0, start_paused=True)
    response = h.call(StepSimulation, 'run', StepSimulation.Request(steps=23))
    assert response.success, response.message
    assert _ns(response.sim_time) == 25 * 2_000_000  # rounded up to 5 periods of 5 steps
    spin_until(h.executor, lambda: h.sim.sim.steps >= 25, TIMEOUT, 'the run')
    for _ in range(20):
        h.executor.spin_once(timeout_sec=0.01)
    assert h.sim.sim.steps == 25  # paused there
    refused = h.call(StepSimulation, 'run', StepSimulation.Request(steps=0))
    assert not refused.success and 'steps must be in [1, 100000]' in refused.message
    for _ in range(20):
        h.executor.spin_once(timeout_sec=0.01)
    assert h.sim.sim.steps == 25 and h.sim._lockstep.paused  # the refusal changed nothing
    assert h.call(StepSimulation, 'run', StepSimulation.Request(steps=100_000)).success
    assert h.call(SetBool, 'set_paused', SetBool.Request(data=True)).success  # ends it early
    steps = h.sim.sim.steps
    for _ in range(20):
        h.executor.spin_once(timeout_sec=0.01)
    assert h.sim.sim.steps == steps < 100_025


@pytest.mark.parametrize('change, message', [
    ({'height': math.nan}, 'height must be a finite number'), ({'height': -0.1}, 'height'),
    ({'distance': 0.0, 'height': 0.05}, 'overlap'), ({'yaw': 2.0}, 'yaw')])
def test_bad_spawn_is_refused_with_a_message_and_changes_nothing(harness_factory, change,
                                                                 message):
    h = harness_factory(lockstep=True, lockstep_timeout=0.0)
    fields = {'name': '', 'height': 0.05, 'depth': 0.5, 'width': 1.0, 'distance': 0.3,
              'yaw': 0.0, 'friction': 1.0}
    fields.update(change)
    response = h.call(SpawnObstacle, 'spawn_obstacle',
                      SpawnObstacle.Request(obstacle=StepObstacle(**fields)))
    assert not response.success
    assert message in response.message
    assert h.sim.sim.obstacle_names == ()


def test_spawn_remove_and_reset_services(harness_factory):
    h = harness_factory(lockstep=True, lockstep_timeout=0.0)
    spawn = h.call(SpawnObstacle, 'spawn_obstacle', SpawnObstacle.Request(
        obstacle=StepObstacle(name='kerb', height=0.05, depth=0.5, width=1.0, distance=0.3,
                              yaw=0.2, friction=1.0)))
    assert spawn.success and spawn.name == 'kerb'
    duplicate = h.call(SpawnObstacle, 'spawn_obstacle', SpawnObstacle.Request(
        obstacle=StepObstacle(name='kerb', height=0.05, depth=0.5, width=1.0, distance=0.3,
                              yaw=0.0, friction=1.0)))
    assert not duplicate.success and 'exists' in duplicate.message
    bad_reset = h.call(ResetSimulation, 'reset', ResetSimulation.Request(x=math.inf))
    assert not bad_reset.success and 'finite' in bad_reset.message
    reset = h.call(ResetSimulation, 'reset', ResetSimulation.Request(x=-1.0, y=0.5, yaw=0.3))
    assert reset.success
    # Single precision (physics.py): a float32 near 1 m resolves 1.2e-7 m; two of those
    # measured here, the bound is eight.
    assert h.sim.sim.state().position[0] == pytest.approx(-1.0, abs=1e-6)
    assert h.sim.sim.obstacle_names == ('kerb',)
    missing = h.call(RemoveObstacle, 'remove_obstacle', RemoveObstacle.Request(name='wall'))
    assert not missing.success and 'no obstacle' in missing.message
    assert h.call(RemoveObstacle, 'remove_obstacle', RemoveObstacle.Request(name='')).success
    assert h.sim.sim.obstacle_names == ()


def test_reset_announces_the_first_state_of_the_new_world_and_drops_older_commands(
        harness_factory):
    """
    A controller learns of a reset from sim/reset_event, heard before the state it names.

    That state has a stamp of its own, so the answer to a state before the reset (still on its
    way) is dropped, not applied to the reset car.
    """
    h = harness_factory(lockstep=True, lockstep_timeout=0.0)
    heard = []
    h.client.create_subscription(Header, 'sim/reset_event',
                                 lambda msg: heard.append(('reset', _ns(msg.stamp))), 10)
    h.client.create_subscription(JointState, 'joint_states',
                                 lambda msg: heard.append(('state', _ns(msg.header.stamp))), 50)
    before = _lockstep_run(h, 20)
    assert before.position[0] > 0.03  # the swivel turned
    reset = h.call(ResetSimulation, 'reset', ResetSimulation.Request(x=0.5))
    assert reset.success, reset.message
    first = 21 * 10**7
    spin_until(h.executor, lambda: ('state', first) in heard, TIMEOUT, 'the state after it')
    assert heard.index(('reset', first)) < heard.index(('state', first))
    after = h.joint_states[-1]
    assert _ns(after.header.stamp) == first and abs(after.position[0]) < 1e-3
    h.command(before.header.stamp, swivel_torque=10.0, drive_speed=5.0)
    for _ in range(20):
        h.executor.spin_once(timeout_sec=0.01)
    assert h.call(StepSimulation, 'step', StepSimulation.Request(steps=5)).success
    spin_until(h.executor, lambda: _ns(h.joint_states[-1].header.stamp) == first + 10**7,
               TIMEOUT, 'the stepped state')
    assert h.joint_states[-1].effort[0] == 0.0
    assert abs(h.joint_states[-1].velocity[1]) < 0.05


def test_lockstep_timeout_advances_and_the_watchdog_stops_the_drive(harness_factory):
    # No controller answers: the sim advances after lockstep_timeout (wall) and a single
    # command acts until the watchdog (sim time) expires.
    h = harness_factory(lockstep=True, lockstep_timeout=0.1, watchdog_timeout=0.05)
    spin_until(h.executor, lambda: h.joint_states, TIMEOUT, 'first joint_states')
    h.command(h.joint_states[-1].header.stamp, swivel_torque=3.0, drive_speed=5.0)
    spin_until(h.executor, lambda: h.sim.sim.time > 0.12, TIMEOUT, 'periods on timeout')
    assert any(m.effort[0] == 3.0 for m in h.joint_states)
    assert h.sim.sim.watchdog_tripped
    assert h.joint_states[-1].effort[0] == 0.0


def test_after_a_lockstep_timeout_the_sim_runs_at_real_time_until_a_command_comes(
        harness_factory, capfd):
    # Before, it advanced one period per lockstep_timeout: with a killed controller, 1 s of
    # sim time took 100 timeouts.
    h = harness_factory(lockstep=True, lockstep_timeout=1.0)
    spin_until(h.executor, lambda: h.sim.sim.time > 0.5, TIMEOUT, '50 periods on one timeout')
    # A command, even for a state already past, brings the lockstep back: the sim waits for
    # the command of its state again (here, for less than lockstep_timeout).
    h.command(h.joint_states[-1].header.stamp, swivel_torque=1.0, drive_speed=0.0)
    states = []
    for wait in (0.1, 0.3):
        end = time.monotonic() + wait
        while time.monotonic() < end:
            h.executor.spin_once(timeout_sec=0.01)
        states.append(_ns(h.joint_states[-1].header.stamp))
    assert states[0] == states[1]
    log = capfd.readouterr().err
    assert log.index(LOCKSTEP_TIMED_OUT_LOG) < log.index(LOCKSTEP_RESUMED_LOG), log


@pytest.mark.parametrize('name, value, message', [
    ('time_step', -0.001, 'time_step'), ('control_period', 0.003, 'control_period'),
    ('real_time_factor', -1.0, 'real_time_factor'), ('robot_variant', 'tank', 'robot_variant'),
    ('h', math.nan, 'h'), ('imu_rate', 30.0, 'imu_rate')])
def test_bad_parameters_are_refused_at_start(name, value, message):
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=next_domain_id())
    try:
        with pytest.raises(ValueError, match=message):
            SimNode(context=context, parameter_overrides=[Parameter(name, value=value)])
    finally:
        rclpy.try_shutdown(context=context)


def test_frame_ids_are_parameters(harness_factory):
    h = harness_factory(lockstep=False, world_frame_id='map', base_frame_id='robot1/base_link')
    spin_until(h.executor, lambda: h.odom and h.imu, TIMEOUT, 'ground truth and imu')
    assert (h.odom[-1].header.frame_id, h.odom[-1].child_frame_id) == ('map',
                                                                       'robot1/base_link')
    assert h.imu[-1].header.frame_id == 'robot1/base_link'


def _answer_every_state(h: Harness, periods: int) -> None:
    """Answer each new state as a controller would until ``periods`` have passed."""
    spin_until(h.executor, lambda: h.joint_states, TIMEOUT, 'first joint_states')
    answered = set()
    while h.sim.sim.steps < periods * 5:
        latest = h.joint_states[-1]
        if _ns(latest.header.stamp) not in answered:
            answered.add(_ns(latest.header.stamp))
            h.command(latest.header.stamp, swivel_torque=60.0 * (0.4 - latest.position[0]),
                      drive_speed=4.0)
        h.executor.spin_once(timeout_sec=0.05)


def test_lockstep_with_the_realistic_sensors_is_deterministic(harness_factory):
    runs = []
    for _ in range(2):
        h = harness_factory(lockstep=True, lockstep_timeout=0.0, sensor_profile='realistic',
                            sensor_seed=3)
        _answer_every_state(h, 60)
        runs.append((h.sim.sim.state(), h.joint_states[-1]))
    (truth, first), (truth2, second) = runs
    assert list(truth.positions) == list(truth2.positions)
    assert list(first.position) == list(second.position)
    assert list(first.velocity) == list(second.velocity)
    assert truth.positions[0] > 0.03  # the swivel moved
    wheel_tick = 2.0 * math.pi / 1920.0  # [rad] the shipped profile's 64 CPR x 30:1
    swivel_tick = 2.0 * math.pi / 16384.0  # [rad] 14 bit
    assert first.position[1] / wheel_tick == pytest.approx(round(
        first.position[1] / wheel_tick), abs=1e-6)
    assert first.position[0] / swivel_tick == pytest.approx(round(
        first.position[0] / swivel_tick), abs=1e-6)
    assert first.position[0] != truth.positions[0]


def _realistic_with(tmp_path, drop_rate: float) -> str:
    """Write the shipped realistic profile with another ``drop_rate``; return its path."""
    import yaml
    from swivel_car_sim.sensor_models import shipped_profile
    data = yaml.safe_load(shipped_profile('realistic').read_text())
    data['transport']['drop_rate'] = drop_rate
    profile = tmp_path / 'profile.yaml'
    profile.write_text(yaml.safe_dump(data))
    return str(profile)


def test_a_lost_state_does_not_hold_up_lockstep(harness_factory, tmp_path):
    # lockstep_timeout 0 waits forever: a lost state that stalled the chain would hang here.
    h = harness_factory(lockstep=True, lockstep_timeout=0.0,
                        sensor_profile=_realistic_with(tmp_path, 0.3))
    _answer_every_state(h, 40)
    stamps = sorted({_ns(m.header.stamp) for m in h.joint_states})
    assert len(stamps) < 40  # 30 % lost: P(none of 40) = 0.7^40 < 1e-6 (and seeded)
    assert h.sim.sim.steps >= 40 * 5


def test_wall_clock_stamps_from_the_system_clock_without_clock(harness_factory):
    start = time.time_ns()
    h = harness_factory(clock_source='wall', sensor_profile='realistic')
    spin_until(h.executor, lambda: len(h.joint_states) > 20, TIMEOUT, 'joint_states')
    h.command(h.joint_states[-1].header.stamp, drive_speed=5.0)
    received = time.time_ns()
    stamps = [_ns(m.header.stamp) for m in h.joint_states]
    # Samples of the system clock: after the start, never in the future.
    assert start <= stamps[0] and stamps[-1] <= received
    # The physics' cadence: stamps advance in whole control periods (more than one where a
    # state was lost, or a busy machine's backlog was caught up unpublished).
    assert all(b > a and (b - a) % 10_000_000 == 0 for a, b in zip(stamps, stamps[1:]))
    assert not h.clock
    spin_until(h.executor, lambda: h.joint_states[-1].velocity[1] > 1.0, TIMEOUT,
               'the command applied')


def test_wall_clock_refuses_run_and_a_stamp_older_than_the_watchdog(harness_factory):
    h = harness_factory(clock_source='wall', start_paused=True)
    response = h.call(StepSimulation, 'run', StepSimulation.Request(steps=50))
    assert not response.success and 'set_paused' in response.message
    assert h.call(SetBool, 'set_paused', SetBool.Request(data=False)).success
    old = time.time_ns() - 600_000_000  # [ns] computed 0.6 s ago, by the system clock
    h.command(Time(sec=old // 10**9, nanosec=old % 10**9), drive_speed=5.0)
    spin_until(h.executor, lambda: h.sim.sim.time > 0.05, TIMEOUT, 'running')
    assert h.sim.sim.state().velocities[1] == pytest.approx(0.0, abs=0.05)


def test_wall_clock_after_a_stall_the_rates_span_the_gap_the_robot_moved_through(
        harness_factory, tmp_path):
    """
    A stalled executor (a loaded machine): the sim catches the physics up, states unpublished.

    The robot went on moving meanwhile, as a real one does, so the first state after the gap
    carries the wheel rate over it: rate times stamp gap is the distance the wheel turned,
    which the odometry integrates. (Skipping the backlog instead had the stamps jump 0.3 s
    while the wheel turned for 0.01 s.)
    """
    # No losses: a lost state is sampled, and the rate of the next spans only its period.
    h = harness_factory(clock_source='wall', sensor_profile=_realistic_with(tmp_path, 0.0),
                        watchdog_timeout=0.0)
    spin_until(h.executor, lambda: h.joint_states, TIMEOUT, 'first joint_states')
    h.command(h.joint_states[-1].header.stamp, drive_speed=5.0)
    spin_until(h.executor, lambda: h.joint_states[-1].velocity[1] > 4.0, TIMEOUT, 'rolling')
    count = len(h.joint_states)
    time.sleep(0.3)  # [s] the stall: nothing spins
    # States in flight at the stall arrive after it: the stall is the largest stamp gap.
    spin_until(h.executor, lambda: len(h.joint_states) > count + 10, TIMEOUT, 'states after')
    pairs = list(zip(h.joint_states[count - 1:], h.joint_states[count:]))
    before, after = max(pairs, key=lambda pair: _ns(pair[1].header.stamp)
                        - _ns(pair[0].header.stamp))
    gap = (_ns(after.header.stamp) - _ns(before.header.stamp)) * 1e-9  # [s]
    assert gap > 0.2
    turned = after.position[1] - before.position[1]  # [rad]
    assert after.velocity[1] * gap == pytest.approx(turned, abs=1e-9)
    # The wheel kept moving, at least at its rate before (it was still speeding up towards
    # the command); 0.9: one tick in a period is 0.33 rad/s, 8 % of that rate.
    assert turned > 0.9 * before.velocity[1] * gap
