"""
The sim node's parameters.

One table (name, default, description) and the validated, frozen configuration read from
it. ROS-free.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from swivel_car_model import description
from swivel_car_model.checks import check_finite_number, check_nonempty_string
from swivel_car_model.description import described
from swivel_car_sim.physics import SimConfig
from swivel_car_sim.sensor_models import SensorProfile

CLOCK_SOURCES = ('sim', 'wall')


@dataclass(frozen=True)
class SimParameters:
    """
    The sim node's own parameters.

    Each field's default and description are its ROS parameter's; ``SimNodeConfig.from_values``
    validates them all.
    """

    gui: bool = described(False, 'open the pybullet GUI window (needs a display)')
    time_step: float = described(0.002, '[s] physics step')
    control_period: float = described(
        0.01, '[s] joint_states/imu/odom period and lockstep advance; a multiple of time_step')
    real_time_factor: float = described(
        1.0, '[1] sim time per wall time when free running; 0 = as fast as possible')
    lockstep: bool = described(
        False, 'advance one control_period per ActuatorCommand stamped with the last '
        'joint_states stamp')
    lockstep_timeout: float = described(
        1.0, '[s] wall time to wait for the command in lockstep (or free running, see '
        'max_command_age); then the sim runs at real time (free running: at real_time_factor) '
        'until a command comes; 0 = wait forever')
    lockstep_real_time_factor: float = described(
        0.0, '[1] in lockstep, at most this much sim time per wall time, so that nodes outside '
        'the lockstep keep up; 0 = as fast as the controller answers')
    max_command_age: float = described(
        0.01, '[s] sim time; free running with clock_source sim: the sim steps on from a state '
        'only while its newest actuator_command answers a state at most this much older, else it '
        'waits for the controller (at most lockstep_timeout), and it drops older commands; 0 = '
        'the command of the state itself')
    watchdog_timeout: float = described(
        0.5, '[s] sim time without a command after which the swivel torque is zeroed and the '
        'drive stops; 0 disables')
    robot_variant: str = described(
        'swivel', "'swivel' or 'car_like' (baseline with a steered front axle)")
    initial_x: float = described(0.0, '[m] initial base_link x in the world')
    initial_y: float = described(0.0, '[m] initial base_link y in the world')
    initial_yaw: float = described(0.0, '[rad] initial heading')
    start_paused: bool = described(
        False, 'start with the physics paused (~/set_paused false resumes)')
    clock_rate: float = described(
        10.0, '[Hz] /clock publish rate (sim time); control_period divided by a whole number. 10 '
        'Hz, as gazebo_ros publishes: each node with use_sim_time takes every message (about 55 '
        'us here), and at 100 Hz the lockstep chain takes 14 % more CPU; sim-time clocks move in '
        'steps of 1/clock_rate')
    imu_rate: float = described(
        100.0, '[Hz] imu publish rate; control_period divided by a whole number')
    ground_truth_rate: float = described(100.0, '[Hz] ground_truth/odom publish rate; as imu_rate')
    ground_friction: float = described(1.0, '[1] friction coefficient of the ground')
    body_collision: bool = described(
        False, 'give the body collision shapes too, not only the wheels (a phi < 0 robot, whose '
        'belly meets step edges)')
    world_frame_id: str = described('world', 'fixed frame of ground_truth/odom and ~/reset_event')
    base_frame_id: str = described(
        'base_link', 'frame of the robot body: imu, ground_truth/odom child')
    clock_source: str = described(
        'sim', "'sim': stamps of sim time, /clock published; 'wall': as a driver board, stamps "
        'from the system clock, no /clock, free running at real time (no lockstep), every other '
        'node with use_sim_time false')
    sensor_profile: str = described(
        'ideal', "'ideal' (the exact state, commands applied as they come), 'realistic' "
        '(config/sensor_profiles/realistic.yaml: encoders, IMU, latency and losses of named '
        'parts) or a profile YAML path')
    sensor_seed: int = described(
        0, '[1] seed of every draw of the sensor models (lockstep stays deterministic)')


# name -> (default, description). The node declares exactly these: its own, then the robot
# description's (swivel_car_model.description, shared by every node).
PARAMETERS: dict[str, tuple[object, str]] = {
    **description.parameters_of(SimParameters), **description.PARAMETERS}


@dataclass(frozen=True)
class SimNodeConfig:
    """
    Everything the sim node reads from its parameters, validated.

    Attributes mirror ``PARAMETERS``; ``physics`` is the SimConfig built from them,
    ``steps_per_period`` the physics steps per control period and ``clock_every`` /
    ``imu_every`` / ``ground_truth_every`` the number of control periods between those
    messages.
    """

    physics: SimConfig
    control_period: float  # [s]
    steps_per_period: int  # [1]
    real_time_factor: float  # [1]
    lockstep: bool
    lockstep_timeout: float  # [s]
    lockstep_real_time_factor: float  # [1]
    max_command_age: float  # [s] sim time
    initial_pose: tuple[float, float, float]  # [m], [m], [rad]
    start_paused: bool
    clock_every: int  # [1]
    imu_every: int  # [1]
    ground_truth_every: int  # [1]
    world_frame_id: str
    base_frame_id: str
    clock_source: str = 'sim'
    sensors: SensorProfile = SensorProfile('ideal', {}, {})
    sensor_seed: int = 0

    @property
    def wall_clock(self) -> bool:
        """Tell whether the sim stamps with the system clock, as a driver board."""
        return self.clock_source == 'wall'

    @classmethod
    def from_values(cls, values: dict[str, object]) -> 'SimNodeConfig':
        """
        Build from parameter values (missing ones take their default).

        Raises
        ------
        ValueError
            A value is of the wrong type or out of range; the message names it.

        """
        v = {name: values.get(name, default) for name, (default, _) in PARAMETERS.items()}
        for name, (default, _) in PARAMETERS.items():
            value = v[name]
            if isinstance(default, bool):
                if not isinstance(value, bool):
                    raise ValueError(f'{name} must be a bool, got {value!r}')
            elif isinstance(default, int):
                if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                    raise ValueError(f'{name} must be an integer >= 0, got {value!r}')
            elif isinstance(default, float):
                check_finite_number(name, value)
                v[name] = float(value)
            elif not isinstance(value, str):
                raise ValueError(f'{name} must be a string, got {value!r}')
        for name in ('world_frame_id', 'base_frame_id'):
            check_nonempty_string(name, v[name])
        if v['clock_source'] not in CLOCK_SOURCES:
            raise ValueError(f"clock_source must be 'sim' or 'wall', got {v['clock_source']!r}")
        if v['clock_source'] == 'wall':
            if v['lockstep']:
                raise ValueError('lockstep cannot run with clock_source wall: a driver board '
                                 'waits for no one (clock_source sim for lockstep)')
            if v['real_time_factor'] != 1.0:
                raise ValueError('clock_source wall runs at real time: real_time_factor must '
                                 f"be 1.0, got {v['real_time_factor']!r}")
        sensors = SensorProfile.load(v['sensor_profile'])
        robot = description.CarDescription.from_values(
            {name: v[name] for name in description.PARAMETERS})
        physics = SimConfig(
            description=robot, robot_variant=v['robot_variant'], time_step=v['time_step'],
            gui=v['gui'], watchdog_timeout=v['watchdog_timeout'],
            ground_friction=v['ground_friction'], body_collision=v['body_collision'])
        steps = _whole_ratio(v['control_period'], physics.time_step, 'control_period',
                             'time_step')
        if v['real_time_factor'] < 0.0:
            raise ValueError(f'real_time_factor must be >= 0, got {v["real_time_factor"]!r}')
        if v['lockstep_real_time_factor'] < 0.0:
            raise ValueError('lockstep_real_time_factor must be >= 0, got '
                             f'{v["lockstep_real_time_factor"]!r}')
        for name in ('lockstep_timeout', 'max_command_age'):
            if v[name] < 0.0:
                raise ValueError(f'{name} must be >= 0, got {v[name]!r}')
        every = {}
        for name in ('clock_rate', 'imu_rate', 'ground_truth_rate'):
            if v[name] <= 0.0:
                raise ValueError(f'{name} must be > 0, got {v[name]!r}')
            every[name] = _whole_ratio(1.0 / v[name], v['control_period'], f'1/{name}',
                                       'control_period')
        return cls(physics=physics, control_period=v['control_period'],
                   steps_per_period=steps, real_time_factor=v['real_time_factor'],
                   lockstep=v['lockstep'], lockstep_timeout=v['lockstep_timeout'],
                   lockstep_real_time_factor=v['lockstep_real_time_factor'],
                   max_command_age=v['max_command_age'],
                   initial_pose=(v['initial_x'], v['initial_y'], v['initial_yaw']),
                   start_paused=v['start_paused'], clock_every=every['clock_rate'],
                   imu_every=every['imu_rate'],
                   ground_truth_every=every['ground_truth_rate'],
                   world_frame_id=v['world_frame_id'], base_frame_id=v['base_frame_id'],
                   clock_source=v['clock_source'], sensors=sensors,
                   sensor_seed=v['sensor_seed'])


def _whole_ratio(numerator: float, denominator: float, name: str, of: str) -> int:
    ratio = numerator / denominator
    whole = round(ratio) if math.isfinite(ratio) else 0
    if whole < 1 or abs(ratio - whole) > 1e-6 * max(1.0, ratio):
        raise ValueError(f'{name} ({numerator!r}) must be a whole multiple (>= 1) of {of} '
                         f'({denominator!r})')
    return whole
