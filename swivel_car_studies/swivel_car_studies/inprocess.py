"""
The swivel car stack in one process, without ROS.

The cores the four nodes wrap, wired in the order (``swivel_car_ros.chain.CHAIN``) and on the
control period of the ROS lockstep chain (docs/architecture.md, "Timing: sim time and
lockstep").

One control period of the ROS chain, and of ``InProcessStack``:

1. the sim publishes the state of time t (joint_states, imu, ground_truth/odom);
2. the controller answers it (``JointStateController``): one ``SwivelController.step`` with
   the planner's command stamped with the previous period, giving the actuator command and
   the controller state of t;
3. the odometry integrates the state of t (``JointStateOdometry``);
4. the planner, with all three inputs of t (``core.sync.InputSync``), steps the climb state
   machine once; its command takes effect at the controller's next answer, one period later;
5. the sim applies the actuator command of t and advances one control period.

Every float the cores see is the one the nodes see: times are the messages' stamps
(``sec + nanosec * 1e-9`` of whole physics steps times the time step in nanoseconds), the
odometry's heading goes through its message's quaternion, and the conversions from messages
are the nodes' own ROS-free functions (``swivel_car_planner.core.inputs``,
``swivel_car_control.core.joint_states``). The configuration is the nodes': their installed
parameter files, read like the nodes read them. ``tests/test_inprocess_identity.py`` (in
``make test``) runs one climb through the installed executables and through this stack and
finds the same ground truth, joint positions and actuator commands in every control period,
bit for bit.

Nothing here imports rclpy.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
import math
from pathlib import Path
import time
from typing import Any, Callable, Mapping

import numpy as np
from swivel_car_control.core.controller import ControllerConfig, ControlOutput, SwivelController
from swivel_car_control.core.joint_states import (
    JointStateController, JointStateOdometry, yaw_quaternion)
from swivel_car_control.joints import MissingJointError
from swivel_car_model import description
from swivel_car_model.description import CarDescription
from swivel_car_perception.core.fusion import Pose2D
from swivel_car_planner.core import (
    capability, ClimbPlan, ClimbRequest, ClimbStateMachine, Command, ErrorCode, inputs,
    make_plan, Outcome, PlanError, PlannerConfig, validate_request)
from swivel_car_planner.core.sync import InputSync
from swivel_car_planner.ground_truth import GroundTruth
from swivel_car_ros.chain import CHAIN, ROS_ONLY
from swivel_car_sim.config import PARAMETERS as SIM_PARAMETERS, SimNodeConfig
from swivel_car_sim.physics import SwivelCarSim
from swivel_car_sim.robot_state import RobotState
from swivel_car_sim.sensor_models import DelayedCommands, SensorSuite
from swivel_car_sim.world import StepSpec
from swivel_car_studies.inprocess_detection import InProcessDetection
import yaml

ROBOT_VARIANTS = ('swivel', 'car_like')
# The joint the controller and the odometry steer by, per robot variant (the car-like
# baseline steers a turntable joint; SimSession sets the same).
_STEER_JOINT = {'swivel': 'swivel_joint', 'car_like': 'steering_joint'}
_CLIMB_SLACK = 1.0  # [s] of sim time past the climb's time allowance before giving up


# --- configuration -------------------------------------------------------------------------

def installed_parameters(package: str, executable: str, node: str) -> dict[str, Any]:
    """
    Return the ``ros__parameters`` of ``node`` in its installed parameter file.

    The file is ``share/<package>/config/<executable>.yaml`` (the one the nodes are started
    with).

    Raises
    ------
    FileNotFoundError
        The package is not installed (build the workspace: ``make build``).

    """
    from ament_index_python.packages import PackageNotFoundError, get_package_share_directory
    try:
        share = Path(get_package_share_directory(package))
    except PackageNotFoundError as error:
        raise FileNotFoundError(f'{package} is not installed: build the workspace '
                                f'(make build) and source it') from error
    data = yaml.safe_load((share / 'config' / f'{executable}.yaml').read_text())
    for scope in data.values():  # '/**' or a namespace
        if isinstance(scope, dict) and node in scope:
            return dict(scope[node].get('ros__parameters', {}))
    return {}


def _dataclass_from(cls: type, values: Mapping[str, Any],
                    defaults: Mapping[str, Any] | None = None, cast: Callable | None = None):
    """
    Build ``cls`` from parameter values as the nodes build it.

    A field's value, else the node's default for it (``defaults``), else the field's default.
    """
    kwargs = {}
    for item in fields(cls):
        default = (defaults or {}).get(item.name, item.default)
        value = values.get(item.name, default)
        if isinstance(default, tuple):
            value = tuple(value)
        kwargs[item.name] = cast(value) if cast is not None else value
    return cls(**kwargs)


def _check_names(kind: str, overrides: Mapping[str, Any], known: set[str]) -> None:
    unknown = sorted(set(overrides) - known)
    if unknown:
        raise ValueError(f'unknown {kind} parameter(s) {", ".join(unknown)}; known: '
                         f'{", ".join(sorted(known))}')


@dataclass(frozen=True)
class StackConfig:
    """
    Every core's configuration, as the nodes build theirs from their parameters.

    Attributes
    ----------
    sim : SimNodeConfig
        The sim node's (physics, control period, IMU and ground-truth rates).
    robot : CarDescription
        The robot description every node declares.
    controller : ControllerConfig
    planner : PlannerConfig
    whole_car_limit : float
        The planner's, from its capability table (``capability_file``). # [m]
    steer_joint : str
        The joint the controller and the odometry read ('swivel_joint', or
        'steering_joint' for the car-like baseline); the planner takes it from the
        controller's state.
    rear_left_wheel_joint, rear_right_wheel_joint : str
    yaw_rate_source : str
        The odometry's ('swivel' or 'rear_wheels').
    odometry_publish_rate : float  # [Hz] of joint_states time

    """

    sim: SimNodeConfig
    robot: CarDescription
    controller: ControllerConfig
    planner: PlannerConfig
    whole_car_limit: float
    steer_joint: str
    rear_left_wheel_joint: str
    rear_right_wheel_joint: str
    yaw_rate_source: str
    odometry_publish_rate: float

    @classmethod
    def installed(cls, robot_variant: str = 'swivel',
                  robot: Mapping[str, Any] | None = None,
                  sim: Mapping[str, Any] | None = None,
                  controller: Mapping[str, Any] | None = None,
                  odometry: Mapping[str, Any] | None = None,
                  planner: Mapping[str, Any] | None = None) -> StackConfig:
        """
        Read the installed parameter files with overrides, as ``-p name:=value`` would give.

        Parameters
        ----------
        robot_variant : str
            'swivel' or 'car_like'.
        robot : mapping, optional
            Overrides applied to every node that declares the name (the geometry ``l, h, phi,
            r, mass, ...`` has the same name in every node).
        sim, controller, odometry, planner : mapping, optional
            Overrides of one node's parameters, by their ROS names (README, "Nodes").

        Raises
        ------
        ValueError
            An unknown parameter name, or a value a node would refuse; the message names it.

        """
        if robot_variant not in ROBOT_VARIANTS:
            raise ValueError(f'robot_variant must be one of {ROBOT_VARIANTS}, got '
                             f'{robot_variant!r}')
        robot, sim, controller = dict(robot or {}), dict(sim or {}), dict(controller or {})
        odometry, planner = dict(odometry or {}), dict(planner or {})
        car_names = set(description.PARAMETERS)
        sim_names = set(SIM_PARAMETERS)
        _check_names('robot', robot, car_names | sim_names)
        joint = {'swivel_joint': _STEER_JOINT[robot_variant]}

        sim_values = {**installed_parameters('swivel_car_sim', 'sim_node', 'sim'),
                      **{k: v for k, v in robot.items() if k in sim_names},
                      'robot_variant': robot_variant, **sim}
        _check_names('sim', sim, sim_names)
        sim_config = SimNodeConfig.from_values(sim_values)

        def node_values(package: str, executable: str, node: str,
                        overrides: dict[str, Any], known: set[str]) -> dict[str, Any]:
            installed = installed_parameters(package, executable, node)
            # A ROS-only parameter is accepted, without effect here.
            _check_names(node, overrides, known | set(installed) | ROS_ONLY[node])
            return {**installed, **{k: v for k, v in robot.items() if k in car_names},
                    **joint, **overrides}

        controller_names = car_names | {item.name for item in fields(ControllerConfig)} \
            - {'max_torque'}
        c = node_values('swivel_car_control', 'controller_node', 'controller', controller,
                        controller_names | {'swivel_joint'})
        o = node_values('swivel_car_control', 'odometry_node', 'odometry', odometry,
                        car_names)
        p = node_values('swivel_car_planner', 'planner_node', 'planner', planner,
                        car_names | {item.name for item in fields(PlannerConfig)}
                        | {'capability_file'})
        for name in ('publish_rate', 'rear_left_wheel_joint', 'rear_right_wheel_joint',
                     'yaw_rate_source'):
            if name not in o:
                raise ValueError(f'the odometry parameter {name} is not in the installed '
                                 'odometry_node.yaml')
        robot_description = sim_config.physics.description
        table, _ = capability.table_for(p.get('capability_file', capability.INSTALLED))
        return cls(
            sim=sim_config,
            robot=robot_description,
            controller=_dataclass_from(
                ControllerConfig, {**c, 'max_torque': robot_description.swivel_torque_limit}),
            planner=_dataclass_from(PlannerConfig, p, cast=float),
            whole_car_limit=math.inf if table is None else table.limit,
            steer_joint=c['swivel_joint'],
            rear_left_wheel_joint=o['rear_left_wheel_joint'],
            rear_right_wheel_joint=o['rear_right_wheel_joint'],
            yaw_rate_source=o['yaw_rate_source'],
            odometry_publish_rate=float(o['publish_rate']))


# --- results -------------------------------------------------------------------------------

@dataclass(frozen=True)
class Trajectory:
    """
    Ground truth and actuator commands, one row per control period.

    Attributes
    ----------
    time : numpy.ndarray, shape (n,)
        Sim time of the state, as its stamp in seconds. # [s]
    position : numpy.ndarray, shape (n, 3)
        base_link origin in the world. # [m]
    orientation : numpy.ndarray, shape (n, 4)
        base_link orientation, quaternion x, y, z, w. # [1]
    joint_names : tuple of str
        Steer joint, then the four wheel joints (rear left, rear right, front left, front
        right).
    joint_positions : numpy.ndarray, shape (n, 5)
        In the order of ``joint_names``. # [rad]
    swivel_torque : numpy.ndarray, shape (n,)
        Swivel (steering) torque the controller commanded for the period after the state
        (the sim clamps it to its limit). # [N m]
    drive_speed : numpy.ndarray, shape (n,)
        Drive speed at the wheels the controller commanded for that period. # [rad/s]

    """

    time: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    joint_names: tuple[str, ...]
    joint_positions: np.ndarray
    swivel_torque: np.ndarray
    drive_speed: np.ndarray

    def __len__(self) -> int:
        return len(self.time)

    def between(self, start: float, end: float = math.inf) -> Trajectory:
        """Return the rows with ``start <= time <= end`` [s]."""
        keep = (self.time >= start) & (self.time <= end)
        return Trajectory(self.time[keep], self.position[keep], self.orientation[keep],
                          self.joint_names, self.joint_positions[keep],
                          self.swivel_torque[keep], self.drive_speed[keep])


@dataclass(frozen=True)
class ClimbResult:
    """
    What ``InProcessStack.climb`` returns: the planner's answer and what happened.

    Attributes
    ----------
    success : bool
        The climb ended with all four wheels on top (by the state machine), or a plan-only
        request was planned.
    error_code : ErrorCode
        Why the request was refused or the climb failed; ``NONE`` on success.
    message : str
    plan : ClimbPlan or None
        None when the request was refused before planning finished.
    outcome : Outcome or None
        The state machine's (duration [s], peak torque [N m], energy [J], max pitch [rad],
        distance [m]); None for a refused or plan-only request.
    start_time : float
        Sim time of the climb's first tick (the first state the state machine saw). # [s]
    trajectory : Trajectory
        The climb's control periods, from its first tick to its last.
    steps : tuple of (float, str)
        The state machine's steps (``state_machine.Step`` names) with the sim time each
        began. # [s]

    """

    success: bool
    error_code: ErrorCode
    message: str
    plan: ClimbPlan | None
    outcome: Outcome | None
    start_time: float
    trajectory: Trajectory
    steps: tuple[tuple[float, str], ...] = ()

    def step_window(self, name: str) -> tuple[float, float]:
        """
        Return the sim times [s] from the start of step ``name`` to the start of the next.

        The window ends at the next step's start or the climb's end; (inf, inf) if the climb
        never reached the step.
        """
        for index, (start, step) in enumerate(self.steps):
            if step == name:
                end = (self.steps[index + 1][0] if index + 1 < len(self.steps)
                       else math.inf)
                return start, end
        return math.inf, math.inf


# --- the stack -----------------------------------------------------------------------------

@dataclass
class _Period:
    """What one control period's stages hand on: the state of t and the answers to it."""

    t: float  # [s] the state's stamp
    state: RobotState  # the sim's ground truth
    positions: list[float]  # [rad] the joints as the nodes hear them
    velocities: list[float]  # [rad/s]
    orientation: list[float]  # [1] ground-truth quaternion x, y, z, w
    measured: list[float]  # [1] the imu's quaternion
    rate: list[float]  # [rad/s] the imu's angular velocity
    swivel: Any = None  # the controller's swivel joint reading
    out: ControlOutput | None = None  # the controller's answer; None: a joint missing
    odom_due: bool = False  # the odometry publishes this period


class InProcessStack:
    """
    The sim, controller, odometry and planner cores in one process, in lockstep.

    Parameters
    ----------
    robot_variant : str
        'swivel', or 'car_like' (the baseline with a steered front axle; drive it with
        ``drive``, it has no climb procedure).
    robot : mapping, optional
        Overrides of robot parameters for every node that declares them (``l`` [m], ``h``
        [m], ``phi`` [rad], ``r`` [m], ``mass`` [kg], ...), as ``-p name:=value``.
    sim, controller, odometry, planner : mapping, optional
        Overrides of one node's parameters by their ROS names and units (README, "Nodes"),
        e.g. ``sim={'wheel_friction': 0.8}``, ``planner={'climb_speed': 2.5}``.
    config : StackConfig, optional
        A complete configuration instead of the installed one with overrides.
    profile : bool
        Accumulate the wall time each core takes (``timings``).

    Notes
    -----
    The stack starts at sim time 0 with the robot at rest at the sim's initial pose, and only
    moves forward in whole control periods. Deterministic: the same calls give the same
    floats, and the same as the ROS nodes in lockstep given the same history.

    """

    def __init__(self, robot_variant: str = 'swivel', *,
                 robot: Mapping[str, Any] | None = None,
                 sim: Mapping[str, Any] | None = None,
                 controller: Mapping[str, Any] | None = None,
                 odometry: Mapping[str, Any] | None = None,
                 planner: Mapping[str, Any] | None = None,
                 config: StackConfig | None = None, profile: bool = False) -> None:
        self.config = config or StackConfig.installed(robot_variant, robot, sim, controller,
                                                      odometry, planner)
        c = self.config
        self.control_period = c.sim.control_period  # [s]
        self._steps_per_period = c.sim.steps_per_period
        self._time_step_ns = round(c.sim.physics.time_step * 1e9)  # as sim_node stamps
        self.sim = SwivelCarSim(c.sim.physics, c.sim.initial_pose)
        # The sim's sensor_profile: None for ideal (the state as it is, commands at once).
        self._sensors = (None if c.sim.sensors.ideal
                         else SensorSuite(c.sim.sensors, c.sim.sensor_seed, self.sim.state()))
        self._commands = DelayedCommands(c.sim.physics.time_step)
        self._periods = 0  # control periods published, as sim_node counts them for imu
        self.profile = profile
        self.timings: dict[str, list[float]] = {}  # name -> [total wall s, count]
        self.refused_commands: list[str] = []  # swivel commands the controller refused
        self._rows: list[tuple] = []
        # The depth camera and the step detector, once ``enable_detection`` is called.
        self.detection: InProcessDetection | None = None
        # One control period: each node's stage, in the chain's order.
        self._chain = tuple(getattr(self, f'_{name}_stage') for name in CHAIN)
        self._start_nodes()

    def _start_nodes(self) -> None:
        """Fresh controller, odometry and planner memories (as freshly started nodes)."""
        c = self.config
        self.car = c.robot.model_params()
        self.controller = JointStateController(
            SwivelController(self.car, c.controller), c.steer_joint)
        self.odometry = JointStateOdometry(
            self.car, c.steer_joint, c.rear_left_wheel_joint, c.rear_right_wheel_joint,
            c.yaw_rate_source, c.odometry_publish_rate)
        self._sync = InputSync(inputs.INPUTS, inputs.CONTROLLER_STATE)
        self._attitude = inputs.Attitude(c.planner.attitude_time_constant)
        self._command_heard = -math.inf  # [s] stamp of the last swivel_command
        self.machine: ClimbStateMachine | None = None
        self._detected_climb = False  # the running climb follows the detector
        self._steps: list[tuple[float, str]] = []
        self._cmd_vel: tuple[float, float] | None = None
        self.last_output: ControlOutput | None = None

    def close(self) -> None:
        """Disconnect the physics. Idempotent."""
        self.sim.close()

    def __enter__(self) -> InProcessStack:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # --- time --------------------------------------------------------------------------

    @property
    def time(self) -> float:
        """Sim time of the state the next period starts from, as its stamp [s]."""
        nanoseconds = self.sim.steps * self._time_step_ns
        # What builtin_interfaces/Time(sec, nanosec) becomes in the nodes (sec + nanosec*1e-9).
        return nanoseconds // 1_000_000_000 + (nanoseconds % 1_000_000_000) * 1e-9

    def _periods_for(self, duration: float) -> int:
        if not (math.isfinite(duration) and duration >= 0.0):
            raise ValueError(f'duration must be finite and >= 0 s, got {duration!r}')
        return round(duration / self.control_period)

    # --- the world ---------------------------------------------------------------------

    def reset(self, x: float = 0.0, y: float = 0.0, yaw: float = 0.0) -> None:
        """
        Put the robot at rest at (x [m], y [m], yaw [rad]) in the world.

        Swivel 0, obstacles removed; the controller, odometry (pose 0) and planner start
        afresh. Sim time goes on.

        Raises
        ------
        ValueError
            A non-finite pose; nothing changes.

        """
        self.sim.reset(x, y, yaw, remove_obstacles=True)
        self._commands.clear()
        if self._sensors is not None:
            self._sensors.reset(self.sim.state())
        self._start_nodes()

    def reset_odometry(self) -> None:
        """
        Reset the odometry's pose to the origin and forget its last twist.

        As odometry_node's ``~/reset``; the car does not move.
        """
        self.odometry.odometry.reset()

    def spawn_step(self, height: float, distance: float, yaw: float = 0.0,
                   width: float = 3.0, depth: float = 2.0, friction: float = 1.0,
                   name: str = '') -> str:
        """
        Spawn a rectangular step ahead of the robot, as the sim's ``spawn_obstacle``.

        Parameters
        ----------
        height : float
            Step height. # [m]
        distance : float
            Front axle ground contact to the edge along base_link x. # [m]
        yaw : float
            The edge normal's angle to base_link x. # [rad]
        width, depth : float
            Along the edge and across it. # [m]
        friction : float
            Coulomb friction coefficient of the step's surfaces. # [1]
        name : str
            '' for an automatic one.

        Returns
        -------
        str : the obstacle's name.

        Raises
        ------
        ValueError
            Invalid field, or the step would overlap the robot.

        """
        return self.sim.spawn_obstacle(StepSpec(
            name=name, height=height, depth=depth, width=width, distance=distance, yaw=yaw,
            friction=friction))

    # --- one control period ------------------------------------------------------------

    def _timed(self, name: str, function: Callable, *args):
        if not self.profile:
            return function(*args)
        start = time.perf_counter()
        try:
            return function(*args)
        finally:
            entry = self.timings.setdefault(name, [0.0, 0])
            entry[0] += time.perf_counter() - start
            entry[1] += 1

    def _period(self) -> None:
        """Run the lockstep chain once (module docstring), from the state of ``time``."""
        t = self.time
        state = self.sim.state()
        positions, velocities = state.positions.tolist(), state.velocities.tolist()
        orientation = state.orientation.tolist()
        if self._sensors is not None:
            sample = self._sensors.sample(state)
            if sample.lost:  # no node hears it: the sim goes on with the command it has
                last = self._rows[-1][-2:] if self._rows else (0.0, 0.0)  # [N m], [rad/s]
                self._rows.append((t, *state.position.tolist(), *orientation, *positions,
                                   *last))
                self._commands.step(self.sim, self._steps_per_period, self.sim.set_command)
                self._periods += 1
                return
            positions, velocities = sample.positions.tolist(), sample.velocities.tolist()
            measured, rate = sample.orientation.tolist(), sample.angular_velocity.tolist()
        else:
            measured, rate = orientation, state.angular_velocity.tolist()
        period = _Period(t, state, positions, velocities, orientation, measured, rate)
        for stage in self._chain:
            stage(period)
        self._periods += 1

    def _controller_stage(self, p: _Period) -> None:
        """controller_node: cmd_vel (renewed every period while driving), then the answer."""
        if self._cmd_vel is not None:
            self.controller.core.set_cmd_vel(*self._cmd_vel, p.t)
        try:
            p.swivel, p.out = self._timed('controller', self.controller.answer, p.t,
                                          p.state.joint_names, p.positions, p.velocities)
        except MissingJointError:
            p.out = None  # the node answers with zero torque and drive
        self.last_output = p.out

    def _odometry_stage(self, p: _Period) -> None:
        """odometry_node: integrates the state; publishes when due."""
        try:
            p.odom_due = self._timed('odometry', self.odometry.update, p.t,
                                     p.state.joint_names, p.positions, p.velocities)
        except ValueError:  # MissingJointError too: not updated, nothing published
            p.odom_due = False

    def _planner_stage(self, p: _Period) -> None:
        """planner_node: its three inputs of t; a tick steps the running climb."""
        t, out = p.t, p.out
        ticks = []
        if self._periods % self.config.sim.imu_every == 0:
            ticks += self._sync.add(inputs.IMU, t, self._attitude.update(t, p.measured,
                                                                         p.rate))
        if p.odom_due:
            o = self.odometry.odometry
            ticks += self._sync.add(inputs.ODOM, t, inputs.odom_values(
                o.x, o.y, yaw_quaternion(o.yaw), o.v))
        if out is not None:
            ticks += self._sync.add(inputs.CONTROLLER_STATE, t, inputs.controller_state_values(
                out.set_point, out.swivel_torque, self._command_heard, p.swivel.position,
                p.swivel.rate))
        if self.detection is not None:
            o = self.odometry.odometry
            self.detection.period(self._periods, t, p.state,
                                  Pose2D(o.x, o.y, o.yaw) if p.odom_due else None,
                                  self.machine is not None)
        for tick in ticks:
            self._on_tick(tick)

    def _sim_stage(self, p: _Period) -> None:
        """sim_node: the actuator command of t, one control period of physics."""
        state, out = p.state, p.out
        torque, drive = (out.swivel_torque, out.drive_speed) if out is not None else (0.0, 0.0)
        self._rows.append((p.t, *state.position.tolist(), *p.orientation,
                           *state.positions.tolist(), torque, drive))
        if self._sensors is None:
            self.sim.set_command(torque, drive)
            self._timed('sim', self.sim.step, self._steps_per_period)
        else:
            if not self._sensors.transport.lost():
                self._commands.push(self.sim.steps, self._sensors.transport.command_delay(),
                                    (torque, drive))
            self._timed('sim', self._commands.step, self.sim, self._steps_per_period,
                        self.sim.set_command)

    def _on_tick(self, tick) -> None:
        machine = self.machine
        if machine is None:
            return
        observation = inputs.observation(tick)
        commands = [self._timed('state_machine', machine.update, observation)]
        if self.detection is not None:
            self.detection.planner.follow(machine, observation, tick.time,
                                          self._detected_climb)
        if not self._steps or self._steps[-1][1] != machine.step.name:
            self._steps.append((tick.time, machine.step.name))
        if machine.outcome is not None:
            commands += inputs.end_commands(machine.outcome)
        for command in commands:
            self._command_swivel(command, tick.time)

    def _command_swivel(self, command: Command, stamp: float) -> None:
        """swivel_command to the controller; it applies it from its next answer."""
        self._command_heard = stamp
        try:
            self.controller.core.set_swivel_command(
                float(command.angle), float(command.max_rate), float(command.drive_speed),
                bool(command.hold), stamp, bool(command.free))
        except ValueError as error:  # the node logs it and keeps the previous command
            self.refused_commands.append(f'{stamp:.2f} s: {error}')

    # --- what users do -----------------------------------------------------------------

    def settle(self, duration: float) -> None:
        """
        Let ``duration`` [s] of sim time pass (whole control periods) with no new command.

        The controller holds what it was told last.
        """
        for _ in range(self._periods_for(duration)):
            self._period()

    def drive(self, v: float, omega: float, duration: float) -> None:
        """
        Drive through the controller's cmd_vel path for ``duration`` [s] of sim time.

        The command (v [m/s] forward speed of base_link, omega [rad/s] yaw rate) is renewed every
        control period, stamped with the state's time. Afterwards it is no longer renewed, so the
        controller's cmd_vel deadman stops the car ``cmd_vel_timeout`` later unless ``drive`` is
        called again (``drive(0, 0, t)`` stops at once, the swivel held).

        Raises
        ------
        ValueError
            A non-finite command or duration.

        """
        for name, value in (('v', v), ('omega', omega)):
            if not math.isfinite(value):
                raise ValueError(f'{name} must be finite, got {value!r}')
        periods = self._periods_for(duration)
        self._cmd_vel = (float(v), float(omega))
        try:
            for _ in range(periods):
                self._period()
        finally:
            self._cmd_vel = None

    def enable_detection(self, seed: int = 0) -> None:
        """Put the depth camera on and run the step detector on it, as the ROS stack does."""
        self.detection = InProcessDetection(self.sim, self.config.robot, self.control_period,
                                            seed)

    def climb(self, request: ClimbRequest, use_detected_step: bool = False) -> ClimbResult:
        """
        Ask the planner to climb, as planner_node's climb_step does.

        Validate, plan, and unless ``plan_only`` run the climb state machine until it ends.

        The climb's first tick is the current state (``time``); the car moves from the next
        control period. When it returns, the car holds still (success: the swivel released
        to the controller; failure: stopped, the swivel held where it was).

        Parameters
        ----------
        request : ClimbRequest
            step_height [m], step_distance [m] (front axle contact to the edge), step_yaw
            [rad], plan_only, time_allowance [s] (0: the planner's default).
        use_detected_step : bool
            Climb the detector's latest detection instead of the request's step (needs
            ``enable_detection``), as planner_node does.

        Returns
        -------
        ClimbResult

        """
        start, first_row = self.time, len(self._rows)
        self._steps = []
        self._detected_climb = use_detected_step
        if use_detected_step:
            detected, why = (self.detection.planner.request(request, start,
                                                            self.config.whole_car_limit)
                             if self.detection is not None
                             else (None, 'the depth camera is off (enable_detection)'))
            if detected is None:
                return self._result(False, ErrorCode.NO_STEP_DETECTED, why, None, None, start)
            request = detected
        code, message = validate_request(request, self.config.planner)
        if code != ErrorCode.NONE:
            return self._result(False, code, message, None, None, start)
        try:
            plan = make_plan(self.car, self.config.planner, request,
                             self.config.whole_car_limit)
        except PlanError as error:
            return self._result(False, error.code, error.message, None, None, start)
        if request.plan_only:
            return self._result(True, ErrorCode.NONE, 'plan only: the robot did not move',
                                plan, None, start)
        machine = ClimbStateMachine(self.car, self.config.planner, plan,
                                    request.step_distance, request.step_yaw,
                                    request.time_allowance)
        self.machine = machine
        # As the node: the attitude the climb trusts starts at its first tick's fused angles.
        self._attitude = inputs.Attitude(self.config.planner.attitude_time_constant)
        allowance = (request.time_allowance if request.time_allowance > 0.0
                     else self.config.planner.time_allowance)
        limit = self._periods_for(allowance + _CLIMB_SLACK)
        try:
            for _ in range(limit):
                self._period()
                if machine.outcome is not None:
                    break
        finally:
            self.machine = None
        if machine.outcome is None:  # its inputs stopped (a joint missing): as the node does
            machine.abort(ErrorCode.NOT_READY, 'no complete input for the climb')
        outcome = machine.outcome
        return self._result(outcome.success, outcome.error_code, outcome.message, plan,
                            outcome, start, slice(first_row, len(self._rows)))

    def _result(self, success: bool, code: ErrorCode, message: str, plan: ClimbPlan | None,
                outcome: Outcome | None, start: float,
                rows: slice = slice(0, 0)) -> ClimbResult:
        return ClimbResult(success, ErrorCode(code), message, plan, outcome, start,
                           self.trajectory(rows), tuple(self._steps))

    # --- ground truth --------------------------------------------------------------------

    def trajectory(self, rows: slice = slice(None)) -> Trajectory:
        """
        Return the control periods so far (ground truth and the commands of each).

        ``rows`` selects some by index.
        """
        n = len(self.sim.joint_names)
        selected = self._rows[rows]
        rows = np.array(selected, dtype=float).reshape(len(selected), 1 + 3 + 4 + n + 2)
        return Trajectory(rows[:, 0], rows[:, 1:4], rows[:, 4:8], tuple(self.sim.joint_names),
                          rows[:, 8:8 + n], rows[:, 8 + n], rows[:, 9 + n])

    def ground_truth(self) -> GroundTruth:
        """base_link in the world now."""
        state = self.sim.state()
        return GroundTruth.from_pose(state.position.tolist(), state.orientation.tolist(),
                                     state.linear_velocity.tolist())

    def front_on_top(self, height: float, tolerance: float = 0.015) -> bool:
        """
        Tell from the ground truth whether the front axle is on top of the step.

        The front axle (a wheelbase ahead of base_link) at the height [m] of the step, within
        ``tolerance`` [m].
        """
        car = self.car
        return self.ground_truth().front_on_top(height, car.r, car.wheelbase, tolerance)

    def four_wheels_on_top(self, height: float, tolerance: float = 0.01) -> bool:
        """
        Tell from the ground truth whether all four wheels are on top of the step.

        The rear axle at the height [m] of the step within ``tolerance`` [m], and the car
        level (so the front axle is up too).
        """
        return self.ground_truth().four_wheels_on_top(height, self.car.r,
                                                      tolerance)
