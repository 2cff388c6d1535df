"""
Odometry benchmark: end-pose error against the ground truth on standard routes in the sim.

The routes run in pybullet; ours (tricycle with a variable offset steering wheel) beside a
plain tricycle.

    python -m swivel_car_control.benchmark [--routes straight_5m,turn_on_the_spot]
        [--sensor-profiles ideal,realistic] [--seed 0]

Runs the sim's physics (``swivel_car_sim.physics.SwivelCarSim``, the same class ``sim_node``
wraps) in lockstep with the controller core and the odometry integrators in one process, so
the figures are deterministic and independent of machine load (every route also runs through
the real node executables in ``test/test_system_routes.py``). Each route runs with the sim's
ideal sensors and with its realistic ones (``swivel_car_sim.sensor_models``: quantised
encoders, lost states and commands, command latency), seeded. Prints; asserts nothing.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
import math
import time

import numpy as np
from swivel_car_control.core.controller import ControllerConfig, SwivelController
from swivel_car_model import kinematics
from swivel_car_model.description import CarDescription
from swivel_car_model.params import SwivelCarParams
from swivel_car_model.planar import arc_step, curvature_for_swivel, OffsetTricycleOdometry
from swivel_car_sim.physics import SimConfig, SwivelCarSim
from swivel_car_sim.sensor_models import DelayedCommands, SensorProfile, SensorSuite

CONTROL_PERIOD = 0.01  # [s], as the sim node's default
SWIVEL, REAR_LEFT, REAR_RIGHT = 0, 1, 2  # joint order of SwivelCarSim.state()


@dataclass(frozen=True)
class Segment:
    """
    One command, held for ``duration`` [s].

    ``('cmd_vel', v [m/s], omega [rad/s])`` or ``('swivel', angle [rad], drive_speed [rad/s])``.
    """

    duration: float
    kind: str
    a: float
    b: float


def _circle(theta2: float, speed: float, p: SwivelCarParams) -> list[Segment]:
    period = 2.0 * math.pi / abs(curvature_for_swivel(p, theta2) * speed)
    return [Segment(1.5, 'swivel', theta2, 0.0),
            Segment(period, 'swivel', theta2, speed / p.r)]


def routes(p: SwivelCarParams) -> dict[str, list[Segment]]:
    """Return the standard routes by name."""
    return {
        'straight_5m': [Segment(5.0 / 0.4 + 0.2, 'cmd_vel', 0.4, 0.0)],
        'circle_swivel_0.3': _circle(0.3, 0.5, p),
        'circle_swivel_0.7': _circle(-0.7, 0.4, p),
        'circle_swivel_1.1': _circle(1.1, 0.3, p),
        'figure_eight': [Segment(2.0 * math.pi / 0.4, 'cmd_vel', 0.4, 0.4),
                         Segment(2.0 * math.pi / 0.4, 'cmd_vel', 0.4, -0.4)],
        'turn_on_the_spot': [Segment(2.0 * math.pi / 1.0 + 1.0, 'cmd_vel', 0.0, 1.0)],
        'swivel_sweep_standstill': [Segment(2.0, 'swivel', 1.2, 0.0),
                                    Segment(3.0, 'swivel', -1.2, 0.0),
                                    Segment(2.0, 'swivel', 0.0, 0.0)],
    }


class PlainTricycleOdometry:
    """
    The comparison: a tricycle whose steering wheel sits on the centre line at the wheelbase.

    Its yaw rate is ``omega = v tan(delta) / wheelbase``; it is fed the same steering angle and
    rear wheel rates and integrated the same way (exact arcs of the mean twist).
    """

    def __init__(self, p: SwivelCarParams) -> None:
        self._p = p
        self.x = self.y = self.yaw = 0.0
        self._last: tuple[float, float] | None = None

    def update(self, theta2: float, rear_wheel_rate: float, dt: float) -> None:
        v = self._p.r * rear_wheel_rate
        omega = v * math.tan(kinematics.steering_angle(self._p, theta2)) / self._p.wheelbase
        v_mean, omega_mean = (v, omega) if self._last is None else (
            0.5 * (v + self._last[0]), 0.5 * (omega + self._last[1]))
        dx, dy, dyaw = arc_step(v_mean, omega_mean, self.yaw, dt)
        self.x, self.y, self.yaw = self.x + dx, self.y + dy, self.yaw + dyaw
        self._last = (v, omega)


@dataclass
class RouteResult:
    """End-pose errors of one route. Distances [m], angles [rad]."""

    name: str
    distance: float
    turned: float
    ours: tuple[float, float]  # (position error, heading error)
    rear: tuple[float, float]  # ours with the yaw rate from the rear wheels
    plain: tuple[float, float]

    @staticmethod
    def percent(error: float, distance: float) -> float:
        return 100.0 * error / distance if distance > 1e-3 else math.nan


def _wrap(angle: float) -> float:
    return math.remainder(angle, 2.0 * math.pi)


class ClosedLoop:
    """
    The sim, the controller core and both odometries, stepped in lockstep.

    Parameters
    ----------
    description : CarDescription
        The robot (default: the stack's).
    config : ControllerConfig
    sensors : SensorProfile, optional
        The sim's sensors and links (default: ideal).
    seed : int
        Of the sensor models' draws.

    """

    def __init__(self, description: CarDescription | None = None,
                 config: ControllerConfig | None = None,
                 sensors: SensorProfile | None = None, seed: int = 0) -> None:
        description = description or CarDescription()
        self.p = description.model_params()
        self.config = config or ControllerConfig(cmd_vel_timeout=0.0,
                                                 swivel_command_timeout=0.0)
        self.sim = SwivelCarSim(SimConfig(description=description))
        self.steps_per_period = round(CONTROL_PERIOD / self.sim.config.time_step)
        self.controller = SwivelController(self.p, self.config)
        self.odometry = OffsetTricycleOdometry(self.p)
        self.rear_odometry = OffsetTricycleOdometry(self.p)
        self.plain = PlainTricycleOdometry(self.p)
        self._last_time: float | None = None
        self.sensors = (None if sensors is None or sensors.ideal
                        else SensorSuite(sensors, seed, self.sim.state()))
        self._commands = DelayedCommands(self.sim.config.time_step)

    def close(self) -> None:
        self.sim.close()

    def period(self) -> tuple[object, object]:
        """
        Run one control period: measure, update the odometries, command, step the physics.

        Returns (true state, controller output; None: the state was lost on its way).
        """
        state = self.sim.state()
        positions, velocities = state.positions, state.velocities
        if self.sensors is not None:
            sample = self.sensors.sample(state)
            if sample.lost:  # nobody hears it: the board goes on with the command it has
                self._commands.step(self.sim, self.steps_per_period, self.sim.set_command)
                return state, None
            positions, velocities = sample.positions, sample.velocities
        theta2 = max(-self.p.max_swivel_angle, min(self.p.max_swivel_angle,
                                                   float(positions[SWIVEL])))
        rate = float(velocities[SWIVEL])
        left, right = float(velocities[REAR_LEFT]), float(velocities[REAR_RIGHT])
        rear = 0.5 * (left + right)
        dt = 0.0 if self._last_time is None else state.time - self._last_time
        self._last_time = state.time
        self.odometry.update(theta2, rate, rear, dt)
        self.rear_odometry.update(theta2, rate, rear, dt, right - left)
        self.plain.update(theta2, rear, dt)
        out = self.controller.step(state.time, float(positions[SWIVEL]), rate)
        command = (out.swivel_torque, out.drive_speed)
        if self.sensors is None:
            self.sim.set_command(*command)
        elif not self.sensors.transport.lost():
            self._commands.push(self.sim.steps, self.sensors.transport.command_delay(),
                                command)
        self._commands.step(self.sim, self.steps_per_period, self.sim.set_command)
        return state, out

    def drive(self, name: str, segments: list[Segment], settle: float = 1.0) -> RouteResult:
        """Drive the segments, then stop and settle; errors at the end."""
        start = self.sim.state()
        for odometry in (self.odometry, self.rear_odometry):
            odometry.set_pose(start.position[0], start.position[1], start.yaw)
        self.plain.x, self.plain.y, self.plain.yaw = (start.position[0], start.position[1],
                                                      start.yaw)
        distance = turned = 0.0
        previous = start
        plan = segments + [Segment(settle, 'cmd_vel', 0.0, 0.0)]
        for segment in plan:
            if segment.kind == 'swivel':
                self.controller.set_swivel_command(segment.a, 0.0, segment.b, True,
                                                   self.sim.time)
            else:
                self.controller.set_swivel_command(0.0, 0.0, 0.0, False, self.sim.time)
            for _ in range(int(round(segment.duration / CONTROL_PERIOD))):
                if segment.kind == 'cmd_vel':
                    self.controller.set_cmd_vel(segment.a, segment.b, self.sim.time)
                state, _ = self.period()
                distance += float(np.hypot(*(state.position[:2] - previous.position[:2])))
                turned += abs(_wrap(state.yaw - previous.yaw))
                previous = state
        self.controller.set_swivel_command(0.0, 0.0, 0.0, False, self.sim.time)
        end = self.sim.state()
        x, y, yaw = end.position[0], end.position[1], end.yaw

        def errors(odometry) -> tuple[float, float]:
            return (float(math.hypot(odometry.x - x, odometry.y - y)),
                    abs(_wrap(odometry.yaw - yaw)))

        return RouteResult(name, distance, turned, errors(self.odometry),
                           errors(self.rear_odometry), errors(self.plain))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--routes', default='', help='comma-separated subset of the routes')
    parser.add_argument('--sensor-profiles', default='ideal,realistic',
                        help="comma-separated: 'ideal', 'realistic' or profile YAML paths")
    parser.add_argument('--seed', type=int, default=0, help="the sensor models' seed")
    args = parser.parse_args(argv)
    description = CarDescription()
    chosen = routes(description.model_params())
    if args.routes:
        chosen = {name: chosen[name] for name in args.routes.split(',')}
    try:
        profiles = [SensorProfile.load(name) for name in args.sensor_profiles.split(',')]
    except ValueError as error:
        parser.error(str(error))
    print('end-pose error vs ground truth: position as % of the distance travelled, heading '
          '[rad]\n  ours      = tricycle with a variable offset steering wheel (planar.py)\n'
          '  rear yaw  = ours, yaw rate from the rear wheel rate difference\n'
          '  plain     = tricycle without offset: omega = v tan(delta) / wheelbase')
    print(f"  sensors   = the sim's ideal ones, or a profile's (seed {args.seed})")
    print(f'{"route":25s} {"sensors":>9s} {"dist m":>7s} {"turn rad":>8s} | {"ours %":>7s} '
          f'{"yaw":>6s} | {"rear yaw %":>10s} {"yaw":>6s} | {"plain %":>7s} {"yaw":>6s} | wall s')
    for name, segments in chosen.items():
        for profile in profiles:
            loop = ClosedLoop(description, sensors=profile, seed=args.seed)
            wall = time.monotonic()
            try:
                result = loop.drive(name, segments)
            finally:
                loop.close()
            wall = time.monotonic() - wall
            cells = []
            for width, (position, heading) in ((7, result.ours), (10, result.rear),
                                               (7, result.plain)):
                cells.append(f'{RouteResult.percent(position, result.distance):{width}.3f} '
                             f'{heading:6.4f}')
            sensors = profile.name if len(profile.name) <= 9 else '...' + profile.name[-6:]
            print(f'{name:25s} {sensors:>9s} {result.distance:7.3f} {result.turned:8.3f} | '
                  + ' | '.join(cells) + f' | {wall:6.1f}'
                  + (f'   (abs: ours {result.ours[0]:.4f} m, rear yaw {result.rear[0]:.4f} m, '
                     f'plain {result.plain[0]:.4f} m)' if result.distance < 0.5 else ''))


if __name__ == '__main__':
    main()
