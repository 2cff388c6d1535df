"""
The sim's sensor and transport models: what the hardware's sensors and links make of the truth.

ROS-free; the one sensor-model module of the sim. A profile (``SensorProfile``) is ``ideal``
(the sim's exact state, commands applied at once: today's behaviour), ``realistic`` (the
shipped ``config/sensor_profiles/realistic.yaml``) or a YAML file of the same form. Every
figure in a profile names the part it comes from; the loader refuses a missing, negative or
non-numeric one with one line. One seeded ``numpy.random.Generator`` draws every random
figure, one sample per new state, so a lockstep run is deterministic.

What a realistic profile models, per sample of the state (one per control period):

- wheel encoders: a motor-shaft quadrature encoder behind a gearbox counts whole ticks of the
  wheel's angle; the position is the count times the tick, the rate the count's difference
  over the sample interval (``QuadratureEncoder``);
- the swivel's absolute encoder: the angle rounded to its resolution, the rate likewise a
  difference (``AbsoluteEncoder``);
- the IMU: the gyro's and accelerometer's white noise (noise density), the gyro's turn-on
  bias less what the board's at-rest calibration removes, a slowly wandering gyro bias (bias
  instability, a first-order Gauss-Markov process) and the accelerometer's offset; the
  orientation is the board's own fusion (a Mahony complementary filter: gravity corrects
  roll and pitch, nothing corrects yaw, so yaw drifts), relative to the heading at power on
  (``FusedImu``);
- transport: each state and each command is lost with a small probability, and a command
  takes effect after both legs' latency plus jitter, whole physics steps after it arrives
  (``Transport``). For a controller that answers every state, where the loop's latency sits
  does not matter; the sim puts all of it on the command, so a state keeps the stamp of its
  sample, as a driver board stamps it.

Whatever the profile, the depth camera's reading has a stereo camera's noise, dropouts and
range limits (``StereoDepthNoise``), drawn per frame from a generator seeded with the frame's
stamp, unless the camera's noise is turned off.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np
import yaml

IDEAL = 'ideal'
REALISTIC = 'realistic'
PROFILE_NAMES = (IDEAL, REALISTIC)
STANDARD_GRAVITY = 9.80665  # [m/s^2], the g of datasheets' mg and ug

# section -> figure -> (unit written in the YAML, factor to SI, strictly positive)
FIGURES: dict[str, dict[str, tuple[str, float, bool]]] = {
    'wheel_encoder': {
        'counts_per_motor_revolution': ('[1] quadrature counts', 1.0, True),
        'gear_ratio': ('[1] motor turns per wheel turn', 1.0, True),
    },
    'swivel_encoder': {
        'bits': ('[1] counts per turn = 2**bits', 1.0, True),
    },
    'imu': {
        'gyro_noise_density': ('[deg/s/sqrt(Hz)]', math.pi / 180.0, False),
        'gyro_bias': ('[deg/s] zero-rate offset', math.pi / 180.0, False),
        'gyro_bias_instability': ('[deg/h]', math.pi / 180.0 / 3600.0, False),
        'gyro_bias_correlation_time': ('[s]', 1.0, True),
        'accel_noise_density': ('[ug/sqrt(Hz)]', 1e-6 * STANDARD_GRAVITY, False),
        'accel_bias': ('[mg] zero-g offset', 1e-3 * STANDARD_GRAVITY, False),
        'fusion_gain': ('[1/s]', 1.0, False),
        'calibration_time': ('[s]', 1.0, True),
    },
    'transport': {
        'state_latency': ('[ms]', 1e-3, False),
        'command_latency': ('[ms]', 1e-3, False),
        'jitter': ('[ms]', 1e-3, False),
        'drop_rate': ('[1] fraction of messages lost', 1.0, False),
    },
}


@dataclass(frozen=True)
class SensorProfile:
    """
    The figures of a profile, in SI units; ``figures`` is empty for the ideal profile.

    Attributes
    ----------
    name : str
        'ideal', 'realistic' or the YAML path.
    figures : dict
        ``(section, figure) -> value`` in SI units (rad, rad/s, m/s^2, s, 1), as ``FIGURES``.
    parts : dict
        ``section -> the part its figures come from``.

    """

    name: str
    figures: Mapping[tuple[str, str], float]
    parts: Mapping[str, str]

    @property
    def ideal(self) -> bool:
        """Tell whether this is the sim's exact state, commands applied as they arrive."""
        return not self.figures

    def __getitem__(self, key: tuple[str, str]) -> float:
        return self.figures[key]

    @classmethod
    def load(cls, value: str) -> SensorProfile:
        """
        Return the profile named ``value``: 'ideal', 'realistic' or a YAML file path.

        Raises
        ------
        ValueError
            An unknown name, an unreadable file, a missing section or figure, or a figure
            that is not a finite number >= 0 (> 0 where a zero means nothing); one line.

        """
        if value == IDEAL:
            return cls(IDEAL, {}, {})
        if value == REALISTIC:
            path = shipped_profile(REALISTIC)
        elif value.endswith(('.yaml', '.yml')):
            path = Path(value)
        else:
            raise ValueError(f"sensor_profile must be one of {', '.join(PROFILE_NAMES)} or a "
                             f'.yaml file path, got {value!r}')
        try:
            data = yaml.safe_load(path.read_text())
        except (OSError, yaml.YAMLError) as error:
            raise ValueError(f'sensor profile {value}: cannot read {path}: '
                             f'{str(error).splitlines()[0]}') from error
        return cls.from_dict(value, data)

    @classmethod
    def from_dict(cls, name: str, data: Any) -> SensorProfile:
        """Validate the mapping of a profile file (see ``load``)."""
        if not isinstance(data, dict):
            raise ValueError(f'sensor profile {name}: expected a mapping of the sections '
                             f"{', '.join(FIGURES)}")
        figures, parts = {}, {}
        for section, table in FIGURES.items():
            where = f'sensor profile {name}: {section}'
            entries = data.get(section)
            if not isinstance(entries, dict):
                raise ValueError(f'{where} is missing (a mapping with part and '
                                 f"{', '.join(table)})")
            part = entries.get('part')
            if not isinstance(part, str) or not part.strip():
                raise ValueError(f'{where}.part is missing: name the part the figures come '
                                 'from')
            parts[section] = part
            for figure, (unit, factor, positive) in table.items():
                raw = entries.get(figure)
                if raw is None:
                    raise ValueError(f'{where}.{figure} is missing ({unit})')
                if isinstance(raw, bool) or not isinstance(raw, (int, float)) \
                        or not math.isfinite(raw):
                    raise ValueError(f'{where}.{figure} must be a finite number {unit}, got '
                                     f'{raw!r}')
                if raw < 0.0 or (positive and raw == 0.0):
                    raise ValueError(f"{where}.{figure} must be {'> 0' if positive else '>= 0'}"
                                     f' {unit}, got {raw!r}')
                figures[section, figure] = float(raw) * factor
        if figures['transport', 'drop_rate'] >= 1.0:
            raise ValueError(f'sensor profile {name}: transport.drop_rate must be < 1, got '
                             f"{figures['transport', 'drop_rate']!r}")
        return cls(name, figures, parts)


def shipped_profile(name: str) -> Path:
    """Path of a profile shipped in the package's ``share/.../config/sensor_profiles``."""
    from ament_index_python.packages import get_package_share_directory
    return (Path(get_package_share_directory('swivel_car_sim')) / 'config'
            / 'sensor_profiles' / f'{name}.yaml')


# --- encoders --------------------------------------------------------------------------------

class QuadratureEncoder:
    """
    An incremental encoder: whole ticks of an angle counted from power on.

    Parameters
    ----------
    counts_per_revolution : float
        Ticks per turn of the measured shaft (the wheel's: motor counts times gear ratio). # [1]
    phase : float
        Where in a tick the shaft stood at power on, in ticks, [0, 1). # [1]
    angle : float
        The shaft's angle at power on. # [rad]

    """

    def __init__(self, counts_per_revolution: float, phase: float, angle: float) -> None:
        self.tick = 2.0 * math.pi / counts_per_revolution  # [rad]
        self._phase = phase
        self._zero = self._count(angle)

    def _count(self, angle: float) -> int:
        return math.floor(angle / self.tick + self._phase)

    def position(self, angle: float) -> float:
        """Return the counted position [rad] of the true ``angle`` [rad]."""
        return (self._count(angle) - self._zero) * self.tick


class AbsoluteEncoder:
    """An absolute encoder of ``bits`` bits: the angle rounded to 2 pi / 2**bits."""

    def __init__(self, bits: float) -> None:
        self.tick = 2.0 * math.pi / 2.0 ** bits  # [rad]

    def position(self, angle: float) -> float:
        """Return the angle read [rad] at the true ``angle`` [rad]."""
        return round(angle / self.tick) * self.tick


# --- the IMU ---------------------------------------------------------------------------------

def quaternion_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a b`` of quaternions (x, y, z, w)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz])


def quaternion_conjugate(q: np.ndarray) -> np.ndarray:
    """Inverse of a unit quaternion (x, y, z, w)."""
    return np.array([-q[0], -q[1], -q[2], q[3]])


def rotation_quaternion(rotation: np.ndarray) -> np.ndarray:
    """Return the unit quaternion (x, y, z, w) of a rotation vector [rad] (axis x angle)."""
    angle = float(np.linalg.norm(rotation))
    if angle < 1e-12:
        return np.array([0.5 * rotation[0], 0.5 * rotation[1], 0.5 * rotation[2], 1.0])
    axis = rotation / angle
    return np.append(axis * math.sin(0.5 * angle), math.cos(0.5 * angle))


def rotate_into(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Return a world vector ``v`` in the frame whose orientation is ``q`` (x, y, z, w)."""
    return quaternion_multiply(quaternion_multiply(quaternion_conjugate(q), np.append(v, 0.0)),
                               q)[:3]


def yaw_of(q: np.ndarray) -> float:
    """Heading of an orientation (x, y, z, w) about the world z axis [rad]."""
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


class FusedImu:
    """
    A MEMS IMU with the board's fusion filter, as a real IMU board reports it.

    Parameters
    ----------
    profile : SensorProfile
        Its ``imu`` figures.
    rng : numpy.random.Generator
    orientation : numpy.ndarray
        The true orientation (x, y, z, w) at power on; the board reports orientations
        relative to the heading it had then (no magnetometer: yaw has no reference).

    Notes
    -----
    The gyro reads the true rate plus its error: white noise of the noise density (per sample
    of interval dt a standard deviation of density / sqrt(dt), so its integral walks as the
    datasheet's angle random walk), the turn-on bias less the board's estimate of it from
    ``calibration_time`` at rest (residual: the noise's mean over that time), and a
    Gauss-Markov bias of standard deviation ``gyro_bias_instability`` and correlation time
    ``gyro_bias_correlation_time``. The filter integrates the true rotation between samples
    (the board samples far faster than it reports) plus the gyro's error, then turns its
    gravity estimate towards the accelerometer's reading at ``fusion_gain`` (Mahony's
    proportional term: roll and pitch follow gravity with that bandwidth, yaw is left alone).
    The accelerometer reads the specific force plus its noise and its zero-g offset.

    """

    def __init__(self, profile: SensorProfile, rng: np.random.Generator,
                 orientation: np.ndarray) -> None:
        self._rng = rng
        f = {figure: profile['imu', figure] for figure in FIGURES['imu']}
        self._gyro_density = f['gyro_noise_density']  # [rad/s/sqrt(Hz)]
        self._accel_density = f['accel_noise_density']  # [m/s^2/sqrt(Hz)]
        self._instability = f['gyro_bias_instability']  # [rad/s]
        self._correlation = f['gyro_bias_correlation_time']  # [s]
        self._gain = f['fusion_gain']  # [1/s]
        turn_on = rng.uniform(-f['gyro_bias'], f['gyro_bias'], 3)  # [rad/s]
        estimate = turn_on + rng.normal(0.0, self._gyro_density / math.sqrt(
            f['calibration_time']), 3)  # [rad/s]
        self._gyro_residual = turn_on - estimate  # [rad/s]
        self._gyro_wander = rng.normal(0.0, self._instability, 3)  # [rad/s]
        self._accel_bias = rng.uniform(-f['accel_bias'], f['accel_bias'], 3)  # [m/s^2]
        q = np.asarray(orientation, dtype=float)
        # Power on: the heading is the board's zero, roll and pitch as they are.
        self._to_board = rotation_quaternion(np.array([0.0, 0.0, -yaw_of(q)]))
        self._true = q
        self.orientation = quaternion_multiply(self._to_board, q)  # [1] x, y, z, w

    def update(self, orientation: np.ndarray, angular_velocity: np.ndarray,
               specific_force: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray,
                                                               np.ndarray]:
        """
        Sample the IMU ``dt`` [s] after the last sample.

        Parameters
        ----------
        orientation : numpy.ndarray
            True orientation (x, y, z, w).
        angular_velocity : numpy.ndarray
            True rate in the body frame. # [rad/s]
        specific_force : numpy.ndarray
            True specific force in the body frame. # [m/s^2]
        dt : float
            > 0. # [s]

        Returns
        -------
        (orientation, angular_velocity, linear_acceleration) as the board reports them.

        """
        rng = self._rng
        decay = math.exp(-dt / self._correlation)
        self._gyro_wander = (decay * self._gyro_wander + self._instability * math.sqrt(
            1.0 - decay * decay) * rng.standard_normal(3))
        gyro_error = (self._gyro_residual + self._gyro_wander
                      + self._gyro_density / math.sqrt(dt) * rng.standard_normal(3))
        accel = (np.asarray(specific_force, dtype=float) + self._accel_bias
                 + self._accel_density / math.sqrt(dt) * rng.standard_normal(3))
        q_true = np.asarray(orientation, dtype=float)
        motion = quaternion_multiply(quaternion_conjugate(self._true), q_true)
        self._true = q_true
        q = quaternion_multiply(quaternion_multiply(self.orientation, motion),
                                rotation_quaternion(gyro_error * dt))
        norm = float(np.linalg.norm(accel))
        if norm > 1e-6:
            up = rotate_into(q, np.array([0.0, 0.0, 1.0]))
            correction = np.cross(accel / norm, up) * (self._gain * dt)
            q = quaternion_multiply(q, rotation_quaternion(correction))
        self.orientation = q / np.linalg.norm(q)
        return (self.orientation.copy(), np.asarray(angular_velocity, dtype=float) + gyro_error,
                accel)


# --- transport -------------------------------------------------------------------------------

class Transport:
    """
    The links between the driver board and the computer: losses, latency and jitter.

    Each leg's delay is its latency plus a jitter drawn uniformly in [0, ``jitter``].
    """

    def __init__(self, profile: SensorProfile, rng: np.random.Generator) -> None:
        self._rng = rng
        self._drop = profile['transport', 'drop_rate']  # [1]
        self._latency = (profile['transport', 'state_latency']
                         + profile['transport', 'command_latency'])  # [s]
        self._jitter = profile['transport', 'jitter']  # [s]

    def lost(self) -> bool:
        """Draw whether one message is lost."""
        return bool(self._rng.random() < self._drop)

    def command_delay(self) -> float:
        """Draw the delay from a state's sample to its answer's effect [s]."""
        return self._latency + self._jitter * float(self._rng.random() + self._rng.random())


# --- the depth camera ------------------------------------------------------------------------

@dataclass(frozen=True)
class StereoDepthNoise:
    """
    The depth error of a RealSense D435-class active stereo camera.

    Its RMS error grows with the square of the depth, sigma_z = z^2 * subpixel / (f * B)
    (Intel RealSense D400 Series datasheet, depth RMS error; Grunnet-Jepsen et al., "Tuning
    depth cameras for best performance"), with the focal length of the native image even
    when the image is decimated after capture: about 0.9, 3.8, 8.5 and 15 mm at 0.5, 1, 1.5
    and 2 m. A pixel has no return (NaN) with probability ``dropout``, nearer than
    ``min_range`` or farther than ``max_range``.

    Attributes
    ----------
    focal_length : float
        At the native 848 x 480 (D435 depth module, 87 x 58 deg). # [px]
    baseline : float
        D435 stereo baseline. # [m]
    subpixel : float
        RMS disparity error of a well-textured scene (datasheet 0.08-0.1). # [px]
    dropout : float
        Pixels without a return on surfaces in range (~1 % on matte, lit surfaces). # [1]
    min_range : float
        Min-Z: ~0.28 m at 1280 x 720 (datasheet), proportional to the capture width. # [m]
    max_range : float
        The datasheet's ~10 m. # [m]

    """

    focal_length: float = 424.0  # [px]
    baseline: float = 0.050  # [m]
    subpixel: float = 0.08  # [px]
    dropout: float = 0.01  # [1]
    min_range: float = 0.28 * 848.0 / 1280.0  # [m]
    max_range: float = 10.0  # [m]

    def sigma(self, depth: np.ndarray) -> np.ndarray:
        """RMS error [m] at ``depth`` [m] along the optical axis."""
        return np.square(depth) * (self.subpixel / (self.focal_length * self.baseline))

    def apply(self, depth: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """
        Return the camera's reading (float32 [m], NaN: no return) of the true ``depth`` [m].

        ``depth`` is NaN where nothing is in view. Draws one normal and one uniform number
        per pixel from ``rng``, whatever the scene, so a seeded frame reads the same each time.
        """
        true = np.asarray(depth, dtype=np.float64)
        noise = rng.standard_normal(true.shape)
        lost = rng.random(true.shape) < self.dropout
        reading = true + self.sigma(true) * noise
        lost |= ~((true >= self.min_range) & (true <= self.max_range))
        return np.where(lost, np.nan, reading).astype(np.float32)


# --- the whole set of a sim ------------------------------------------------------------------

@dataclass(frozen=True)
class Sample:
    """
    What the hardware reports of one state.

    ``lost``: the joint_states (and imu) of this sample never arrive.
    """

    positions: np.ndarray  # [rad] steer joint, then the wheel joints
    velocities: np.ndarray  # [rad/s]
    orientation: np.ndarray  # [1] x, y, z, w
    angular_velocity: np.ndarray  # [rad/s]
    linear_acceleration: np.ndarray  # [m/s^2]
    lost: bool


class SensorSuite:
    """
    The robot's sensors and links under a non-ideal profile.

    Parameters
    ----------
    profile : SensorProfile
        Not ideal.
    seed : int
        Of the one generator every draw comes from.
    state : RobotState-like
        The state at power on (``time``, ``positions``, ``orientation``); joint 0 is the steer
        joint (absolute encoder), the others wheels (quadrature encoders).

    Notes
    -----
    ``sample`` draws once per new sample time, in a fixed order, and returns the same sample
    for the same time again (a republished state), so the draws follow sim time only.

    """

    def __init__(self, profile: SensorProfile, seed: int, state: Any) -> None:
        if profile.ideal:
            raise ValueError('the ideal profile has no sensor models')
        self.profile = profile
        self._rng = np.random.default_rng(seed)
        self.transport = Transport(profile, self._rng)
        self._power_on(state)

    def _power_on(self, state: Any) -> None:
        counts = (self.profile['wheel_encoder', 'counts_per_motor_revolution']
                  * self.profile['wheel_encoder', 'gear_ratio'])
        positions = np.asarray(state.positions, dtype=float)
        self._steer = AbsoluteEncoder(self.profile['swivel_encoder', 'bits'])
        self._wheels = [QuadratureEncoder(counts, float(self._rng.random()), float(angle))
                        for angle in positions[1:]]
        self.imu = FusedImu(self.profile, self._rng, np.asarray(state.orientation))
        self._last: Sample | None = None
        self._last_time = float(state.time)  # [s]
        self._last_positions = self._read(positions)

    def reset(self, state: Any) -> None:
        """Power the sensors on again at ``state`` (a sim reset: a new world)."""
        self._power_on(state)

    def _read(self, positions: np.ndarray) -> np.ndarray:
        return np.array([self._steer.position(float(positions[0]))]
                        + [wheel.position(float(angle))
                           for wheel, angle in zip(self._wheels, positions[1:])])

    def sample(self, state: Any) -> Sample:
        """Return what the hardware reports of ``state`` (RobotState), sampled at its time."""
        dt = float(state.time) - self._last_time  # [s]
        if self._last is not None and dt <= 0.0:
            return self._last
        positions = self._read(np.asarray(state.positions, dtype=float))
        if dt > 0.0:
            velocities = (positions - self._last_positions) / dt
            orientation, rate, accel = self.imu.update(
                state.orientation, state.angular_velocity, state.linear_acceleration, dt)
        else:  # the first sample at power on
            velocities = np.zeros_like(positions)
            orientation = self.imu.orientation.copy()
            rate = np.asarray(state.angular_velocity, dtype=float)
            accel = np.asarray(state.linear_acceleration, dtype=float)
        self._last_time, self._last_positions = float(state.time), positions
        self._last = Sample(positions, velocities, orientation, rate, accel,
                            self.transport.lost())
        return self._last


class DelayedCommands:
    """
    Commands on their way to the actuators, applied at whole physics steps.

    ``push`` a command at the step it arrives with its delay; ``due`` gives each command whose
    step has come, in order of arrival.
    """

    def __init__(self, time_step: float) -> None:
        self._time_step = time_step  # [s]
        self._queue: list[tuple[int, tuple[float, float]]] = []

    def push(self, step: int, delay: float, command: tuple[float, float]) -> None:
        """Queue ``command`` (swivel torque [N m], drive speed [rad/s]) arriving at ``step``."""
        at = step + max(0, round(delay / self._time_step))
        # A later command never overtakes an earlier one on the same link.
        if self._queue:
            at = max(at, self._queue[-1][0])
        self._queue.append((at, command))

    def next_step(self) -> int | None:
        """Return the physics step of the next command due; None: nothing queued."""
        return self._queue[0][0] if self._queue else None

    def due(self, step: int) -> list[tuple[float, float]]:
        """Remove and return the commands due at or before ``step``."""
        ready = [command for at, command in self._queue if at <= step]
        self._queue = [(at, command) for at, command in self._queue if at > step]
        return ready

    def clear(self) -> None:
        """Forget the commands on their way (a sim reset)."""
        self._queue.clear()

    def step(self, sim: Any, steps: int, apply: Callable[[float, float], Any]) -> None:
        """
        Step ``sim`` (a SwivelCarSim) ``steps`` physics steps, each command applied when due.

        ``apply(swivel_torque, drive_speed)`` gives a command to the physics.
        """
        end = sim.steps + steps
        while True:
            for command in self.due(sim.steps):
                apply(*command)
            if sim.steps >= end:
                return
            due = self.next_step()
            sim.step((end if due is None else min(end, max(due, sim.steps + 1))) - sim.steps)
