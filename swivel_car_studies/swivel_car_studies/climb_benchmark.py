"""
Whole-car climbing benchmark in physics: ``python -m swivel_car_studies.climb_benchmark``.

Climbs steps from 2 to 20 cm in 1 cm increments, each from randomised requests (distance from
the front axle to the edge, the edge's yaw, the top face's width and where along the edge it
lies), through the in-process stack (``InProcessStack``: the sim, controller, odometry and
planner cores of the ROS nodes, in lockstep), and prints a table judged by the sim's ground
truth: the front axle on top (the thesis' criterion) and all four wheels on top, level, at
rest. Beside them the swivel torque (peak, measured and predicted by the model; sign changes
while the rear axle climbs, the chatter of the old procedure), the energy, and the car-like
baseline with the same mass layout and drive train driven straight at the same steps. Then
the same table for the phi < 0 design (``swivel_car_model/config/designs/phi_negative.yaml``,
the semi-active procedure of thesis III.B, the body colliding) at ``--phi-negative-heights``,
from far, wide steps: its approach is 0.75-0.94 rad oblique.

Requests the planner refuses before moving because of where the car stands ("refused as
placed": the top face too narrow, no path to where the approach can start) are a column of
their own, the share of the requests drawn at that height, and are drawn again: the climbs
counted are ``--trials`` attempted ones. The whole car's limit is a statistical statement:
the highest height of the unbroken run from the lowest whose lower one-sided 90 %
Clopper-Pearson bound on all four wheels on top is at least 85 %
(``capability.BOUND_RELIABLE``, ``capability.CONFIDENCE``); 40 trials per height put it at
>= 38 of 40. The seed is drawn per run unless ``--seed`` gives it, and printed.
``--write-capability`` writes the planner's capability table
(``swivel_car_planner/config/capability.yaml``) with the command (seed included) and the
statistic in its header. Each height runs in its own in-process stack, ``--workers`` at once
(processes). About 3-6 s of CPU per climb (a repositioning path adds its drive); prints,
asserts nothing. ``--sensor-profiles`` (default ``ideal,realistic``) runs the table once per
sim sensor profile (``swivel_car_sim.sensor_models``: quantised encoders, the fused IMU's
drift, lost messages, late commands; seeded, so lockstep stays deterministic) on the same
draws, and compares all four wheels on top by height; the first profile's trials give
``--write-capability``'s table.
"""

from __future__ import annotations

import argparse
from collections import defaultdict
from dataclasses import dataclass, fields
import math
import multiprocessing
from pathlib import Path
import random
import shlex
import statistics
import sys
import time

from ament_index_python.packages import get_package_share_directory
import numpy as np
from swivel_car_model import kinematics, traction
from swivel_car_model.checks import check_finite_number
from swivel_car_model.description import CarDescription
from swivel_car_planner.core import ClimbRequest, ErrorCode
from swivel_car_planner.core.capability import (
    BOUND_RELIABLE, CapabilityTable, CONFIDENCE, description_values)
from swivel_car_planner.core.reposition import reposition_length
from swivel_car_studies.inprocess import InProcessStack, StackConfig
import yaml

_NOT_ATTEMPTED = (ErrorCode.INVALID_REQUEST,)
_REFUSED = (ErrorCode.UNREACHABLE_HEIGHT, ErrorCode.TIP_OVER, ErrorCode.TORQUE_LIMIT,
            ErrorCode.WHEEL_INTERFERENCE)
_CHATTER_TORQUE = 1.0  # [N m] torque sign changes count between values beyond +-this
_CAR_LIKE_SPEED = 0.5  # [m/s] the baseline's drive speed at the step
_CAR_LIKE_TIME = 6.0  # [s] sim time it drives
_TARGET_HEIGHT = 0.08  # [m] the whole-car climb the product aims at (issue 11)
_WIDE_MARGIN = 0.2  # [m] faces this much wider than the track: the room a user meets
STATISTIC = (f'the unbroken run of heights from the lowest whose lower one-sided '
             f'{CONFIDENCE:.0%} Clopper-Pearson bound on success is >= {BOUND_RELIABLE:.0%}')
PHI_NEGATIVE = (Path(get_package_share_directory('swivel_car_model')) / 'config' / 'designs'
                / 'phi_negative.yaml')


@dataclass(frozen=True)
class Trial:
    height: float  # [m]
    distance: float  # [m]
    yaw: float  # [rad]
    width: float  # [m]
    offset: float  # [m]
    code: ErrorCode
    message: str
    front: bool  # ground truth: the front axle on top
    four: bool  # ground truth: all four wheels on top, level
    peak_torque: float  # [N m] measured: the controller's commanded swivel torque
    energy: float  # [J] measured
    predicted_torque: float  # [N m] model
    predicted_energy: float  # [J] model
    rear_sign_changes: int  # swivel torque sign changes while the rear axle climbs
    rear_peak_torque: float  # [N m] while the rear axle climbs
    backup: float  # [m] the car backed up first this far
    success: bool  # the planner's verdict
    duration: float  # [s] sim time of the climb, 0 when refused
    reposition: float = 0.0  # [m] the car first drove a repositioning path this long


@dataclass(frozen=True)
class RequestRanges:
    """
    Where randomised climb requests are drawn from (uniformly).

    Raises
    ------
    ValueError
        A bound that is not a finite number, a minimum above its maximum, or no width (the
        sim's step needs a top face); the message names it.

    """

    min_distance: float = 0.2  # [m] front axle to the edge
    max_distance: float = 2.0  # [m]
    max_yaw: float = 0.3  # [rad] the edge's yaw, within +-this
    min_width: float = 0.8  # [m] the top face along the edge
    max_width: float = 2.0  # [m]
    max_offset: float = 0.0  # [m] the face centre along the edge, within +-this

    def __post_init__(self) -> None:
        for item in fields(self):
            value = getattr(self, item.name)
            check_finite_number(item.name, value)
        if self.min_width <= 0.0:
            raise ValueError(f'min_width must be > 0, got {self.min_width!r}')
        for low, high in (('min_distance', 'max_distance'), ('min_width', 'max_width')):
            if getattr(self, low) > getattr(self, high):
                raise ValueError(f'{low} must be <= {high}, got {getattr(self, low)!r} > '
                                 f'{getattr(self, high)!r}')

    def draw(self, rng: random.Random) -> tuple[float, float, float, float]:
        """Draw the distance [m], yaw [rad], width [m] and offset [m] of one request."""
        return (rng.uniform(self.min_distance, self.max_distance),
                rng.uniform(-self.max_yaw, self.max_yaw),
                rng.uniform(self.min_width, self.max_width),
                rng.uniform(-self.max_offset, self.max_offset))

    def bounds(self) -> tuple[tuple[float, float, float, float], ...]:
        """Return the lowest and the highest (distance, yaw, width, offset) ``draw`` returns."""
        return ((self.min_distance, -self.max_yaw, self.min_width, -self.max_offset),
                (self.max_distance, self.max_yaw, self.max_width, self.max_offset))


def _track(p) -> float:
    """Return the track: outer edge to outer edge of the wheels [m]."""
    return 2.0 * p.h + p.wheel_width


def heights(start: float, stop: float, step: float) -> list[float]:
    count = int(round((stop - start) / step))
    return [round(start + i * step, 4) for i in range(count + 1)]


def sign_changes(torque: np.ndarray, threshold: float = _CHATTER_TORQUE) -> int:
    """Sign changes of ``torque`` [N m] between values beyond +-``threshold``."""
    signs = np.sign(torque[np.abs(torque) > threshold])
    return int(np.count_nonzero(signs[1:] != signs[:-1]))


def climb_trial(stack: InProcessStack, height: float, distance: float, yaw: float,
                width: float, offset: float) -> Trial:
    """
    Run one climb from where ``stack`` stands.

    The car settles, a step appears ahead, the planner climbs it, the car rests a second, and
    the ground truth judges it.

    Parameters
    ----------
    stack : InProcessStack
        The running stack the climb drives.
    height : float
        Step height. # [m]
    distance : float
        Front axle to the edge. # [m]
    yaw : float
        The edge's yaw. # [rad]
    width : float
        The top face along the edge. # [m]
    offset : float
        The face centre along the edge. # [m]

    """
    stack.settle(0.2)
    stack.spawn_step(height, distance, yaw, width=width, depth=3.0)
    result = stack.climb(ClimbRequest(
        step_height=height, step_distance=distance, step_yaw=yaw,
        step_width=width, step_offset=offset))
    stack.settle(1.0)
    rear = result.trajectory.between(*result.step_window('REAR'))
    outcome, plan = result.outcome, result.plan
    return Trial(
        height, distance, yaw, width, offset, result.error_code, result.message,
        stack.front_on_top(height), stack.four_wheels_on_top(height),
        outcome.peak_torque if outcome else 0.0,
        outcome.energy if outcome else 0.0,
        plan.peak_torque if plan else math.nan,
        plan.energy if plan else math.nan,
        sign_changes(rear.swivel_torque),
        float(np.max(np.abs(rear.swivel_torque), initial=0.0)),
        plan.backup_distance if plan else 0.0,
        result.success, outcome.duration if outcome else 0.0,
        reposition_length(plan.reposition) if plan else 0.0)


def height_trials(config: StackConfig, ranges: RequestRanges, height: float, trials: int,
                  max_draws: int, seed: int) -> list[Trial]:
    """
    Draw requests at ``height`` until ``trials`` are attempted (``max_draws`` times at most).

    One in-process stack of its own; the draws come from ``seed`` alone, so a height's trials
    are the same whichever process runs it.
    """
    rng = random.Random(seed)
    results = []
    attempted = drawn = 0
    with InProcessStack(config=config) as stack:
        while attempted < trials and drawn < trials * max_draws:
            drawn += 1
            distance, yaw, width, offset = ranges.draw(rng)
            stack.reset()
            trial = climb_trial(stack, height, distance, yaw, width, offset)
            if trial.code not in _NOT_ATTEMPTED:
                attempted += 1
            results.append(trial)
            print(f'  {height:.2f} m  d {distance:.2f} m  yaw {yaw:+.2f} rad  width '
                  f'{width:.2f} m  offset {offset:+.2f} m  backup {trial.backup:.2f} m  '
                  f'reposition {trial.reposition:.2f} m: {trial.code.name:<18} front '
                  f'{"up" if trial.front else "--"}  four {"up" if trial.four else "--"}'
                  f'  ({trial.message})', flush=True)
    return results


def run_swivel(args: argparse.Namespace, config: StackConfig, ranges: RequestRanges,
               seed: int) -> list[Trial]:
    """Run every height's trials, ``args.workers`` heights at once; in height order."""
    tasks = [(config, ranges, height, args.trials, args.max_draws, seed * 1000 + index)
             for index, height in enumerate(_heights(args))]
    if args.workers <= 1:
        return [t for task in tasks for t in height_trials(*task)]
    with multiprocessing.get_context('spawn').Pool(args.workers) as pool:
        return [t for result in pool.starmap(height_trials, tasks) for t in result]


def run_car_like(args: argparse.Namespace, robot: dict) -> dict[float, bool]:
    """
    Drive the car-like baseline straight at each step; True where all four wheels end on top.

    Stops after two heights in a row fail (higher ones only fail the more).
    """
    results: dict[float, bool] = {}
    with InProcessStack('car_like', robot=robot) as stack:
        for height in _heights(args):
            stack.reset()
            stack.settle(0.2)
            stack.spawn_step(height, 0.3, depth=10.0)  # deep: it must not drive off the far side
            stack.drive(_CAR_LIKE_SPEED, 0.0, _CAR_LIKE_TIME)
            stack.drive(0.0, 0.0, 1.0)
            results[height] = stack.four_wheels_on_top(height)
            print(f'  car-like {height:.2f} m: {"on top" if results[height] else "stopped"}',
                  flush=True)
            if len(results) >= 2 and not any(list(results.values())[-2:]):
                break
    return results


def table_of(trials: list[Trial], judge, description: CarDescription,
             command: str) -> CapabilityTable:
    """Success of the attempted climbs by height, judged by ``judge(trial)``, bounded."""
    by_height: dict[float, list[Trial]] = defaultdict(list)
    for trial in trials:
        if trial.code not in _NOT_ATTEMPTED:
            by_height[trial.height].append(trial)
    ordered = sorted(by_height)
    return CapabilityTable(
        tuple(ordered), tuple(len(by_height[h]) for h in ordered),
        tuple(sum(bool(judge(t)) for t in by_height[h]) for h in ordered),
        description_values(description), reliable=BOUND_RELIABLE, command=command,
        confidence=CONFIDENCE)


def report(trials: list[Trial], car_like: dict[float, bool],
           description: CarDescription) -> None:
    p = description.model_params()
    by_height: dict[float, list[Trial]] = defaultdict(list)
    for trial in trials:
        by_height[trial.height].append(trial)
    four_table = table_of(trials, lambda t: t.four, description, '')
    bounds = four_table.lower_bounds
    print()
    print('height | refused as placed | n | front up | 4 wheels | lower 90 % bound | '
          'repositioned | peak torque meas / model | energy meas / model | '
          'rear: torque sign changes, peak | car-like | typical failure')
    print('-------|-------------------|---|----------|----------|------------------|'
          '--------------|--------------------------|---------------------|'
          '---------------------------------|----------|----------------')
    for height, drawn in sorted(by_height.items()):
        group = [t for t in drawn if t.code not in _NOT_ATTEMPTED]
        skipped = len(drawn) - len(group)
        refused = f'{skipped:3d} of {len(drawn):3d} ({skipped / len(drawn):4.0%})'
        car = {True: 'on top', False: 'stopped', None: '-'}[car_like.get(height)]
        if not group:
            print(f'{height:.2f} m | {refused} | 0 | every request refused as placed | {car}')
            continue
        n = len(group)
        climbed = [t for t in group if t.code not in _REFUSED]
        if climbed:
            torque = (f'{max(t.peak_torque for t in climbed):5.1f} / '
                      f'{climbed[0].predicted_torque:5.1f} N m')
            energy = (f'{statistics.mean(t.energy for t in climbed):5.1f} / '
                      f'{climbed[0].predicted_energy:5.1f} J')
            rear = (f'{statistics.median(t.rear_sign_changes for t in climbed):4.0f}, '
                    f'{max(t.rear_peak_torque for t in climbed):5.1f} N m')
        else:
            torque = energy = rear = f'refused: {group[0].code.name}'
        failures = [t.code.name if t.code != ErrorCode.NONE else 'NONE but not on top'
                    for t in group if not t.four]
        typical = max(set(failures), key=failures.count) if failures else '-'
        four = sum(t.four for t in group)
        moved = sum(t.reposition > 0.0 for t in group)
        print(f'{height:.2f} m | {refused} | {n} | {sum(t.front for t in group) / n:6.0%}   '
              f'| {four:2d}/{n:<2d} {four / n:4.0%} | {bounds[height]:16.2f} | '
              f'{moved:5d} of {n:<3d} | {torque:>24} | {energy:>19} | {rear:>31} | {car:8} | '
              f'{typical}')
    wide = [t for t in trials if t.width >= _track(p) + _WIDE_MARGIN]
    if wide:
        refused = sum(t.code in _NOT_ATTEMPTED for t in wide)
        print(f'refused as placed, faces at least the track + {_WIDE_MARGIN:.1f} m wide: '
              f'{refused} of {len(wide)} ({refused / len(wide):.1%})')
    model_max, _ = kinematics.max_scalable_step(p, respect_tip_over=True)
    front_best = table_of(trials, lambda t: t.front, description, '').limit
    four_best = four_table.limit
    car_best = max((h for h, ok in car_like.items() if ok), default=0.0)
    print()
    print(f'robot: centre of mass at {description.com_fraction:.0%} of the wheelbase, '
          f'I_s {description.inertia_about_rear_axle:.2f} kg m^2 (thesis 0.84), differentials '
          f'{description.front_differential}/{description.rear_differential}, drive '
          f'{description.drive_torque_limit:.0f} N m, tyre friction {description.wheel_friction}')
    print(f'model max scalable step (tip-over rule kept): {model_max:.3f} m = '
          f'{model_max / p.r:.2f} r')
    print(f'highest step climbed reliably ({STATISTIC}), front axle on top: '
          f'{front_best:.2f} m = {front_best / model_max:.0%} of the model limit')
    print(f'highest step climbed reliably, all four wheels on top: {four_best:.2f} m = '
          f'{four_best / p.r:.2f} r')
    if car_like:
        print(f'car-like baseline, highest step climbed (four wheels): {car_best:.2f} m = '
              f'{car_best / p.r:.2f} r')
    com_height, mu = float(description.com[2]), description.wheel_friction
    quasi_static = traction.trailing_axle_limit(p, description.com_fraction, com_height, mu)
    needed = max(traction.trailing_axle_min_com(p, h, com_height, mu)
                 for h in heights(0.01, _TARGET_HEIGHT, 0.005))
    print(f'rear axle by traction, quasi-static model (swivel_car_model.traction): up to '
          f'{quasi_static:.3f} m with this layout; every step to {_TARGET_HEIGHT:.2f} m needs '
          f'the centre of mass at >= {needed:.0%} of the wheelbase')


def compare_profiles(by_profile: dict[str, list[Trial]]) -> None:
    """
    Print all four wheels on top by height, one column per sensor profile (same draws).

    Each column beside the first's: within one trial in eight of it, or not.
    """
    counts = {}
    for profile, trials in by_profile.items():
        by_height: dict[float, list[bool]] = defaultdict(list)
        for trial in trials:
            if trial.code not in _NOT_ATTEMPTED:
                by_height[trial.height].append(trial.four)
        counts[profile] = by_height
    first, *others = by_profile
    print('\nall four wheels on top, same draws: ' + ' | '.join(by_profile))
    for height in sorted(counts[first]):
        cells, ok = [], True
        for profile in by_profile:
            done = counts[profile].get(height, [])
            cells.append(f'{sum(done):2d}/{len(done):<2d}')
            if profile != first and done:
                base = counts[first][height]
                ok &= sum(done) >= sum(base) - max(1, len(base) / 8)
        print(f'{height:.2f} m | ' + ' | '.join(cells)
              + ('' if not others else f" | {'within' if ok else 'NOT within'} 1 in 8 of "
                 f'{first}'))


def design_values(path: str | Path) -> dict:
    """
    Read the robot description parameters of a design file (``config/designs/*.yaml``).

    A design file is a params file for every node: ``/**: ros__parameters``.
    """
    return dict(yaml.safe_load(Path(path).read_text())['/**']['ros__parameters'])


def _assignments(items: list[str] | None) -> dict:
    """``NAME=VALUE`` arguments as a dict, each value read as YAML."""
    values = {}
    for item in items or []:
        name, _, value = item.partition('=')
        values[name] = yaml.safe_load(value)
    return values


def _robot(args: argparse.Namespace) -> dict:
    robot = {}
    for path in args.design or []:
        robot.update(design_values(path))
    robot.update(_assignments(args.set))
    return robot


def _height(text: str) -> float:
    """Read one step height or height increment [m] of the command line: finite, > 0."""
    value = float(text)
    if not (math.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f'must be a finite height > 0 m, got {text}')
    return value


def _height_list(text: str) -> list[float]:
    """Read comma-separated step heights [m] of the command line (empty items skipped)."""
    return [_height(item) for item in text.split(',') if item]


def _heights(args: argparse.Namespace) -> list[float]:
    return args.heights or heights(args.min_height, args.max_height, args.step)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--min-height', type=_height, default=0.02, help='[m]')
    parser.add_argument('--max-height', type=_height, default=0.20, help='[m]')
    parser.add_argument('--step', type=_height, default=0.01, help='[m]')
    parser.add_argument('--heights', type=_height_list,
                        metavar='H1,H2,...', help='[m] these heights instead of the range')
    parser.add_argument('--trials', type=int, default=40, help='attempted climbs per height')
    parser.add_argument('--max-draws', type=int, default=4,
                        help='draw at most this many times --trials requests per height')
    parser.add_argument('--seed', type=int,
                        help='of the requests drawn; default: drawn for this run (printed)')
    parser.add_argument('--workers', type=int, default=1,
                        help='heights climbed at once, each in a process of its own')
    defaults = RequestRanges()
    parser.add_argument('--min-distance', type=float, default=defaults.min_distance,
                        help='[m]')
    parser.add_argument('--max-distance', type=float, default=defaults.max_distance,
                        help='[m]')
    parser.add_argument('--max-yaw', type=float, default=defaults.max_yaw, help='[rad]')
    parser.add_argument('--min-width', type=float, default=defaults.min_width, help='[m]')
    parser.add_argument('--max-width', type=float, default=defaults.max_width, help='[m]')
    parser.add_argument('--max-offset', type=float, default=defaults.max_offset,
                        help='[m] the face centre along the edge, drawn within +-this')
    parser.add_argument('--design', action='append', metavar='YAML',
                        help='a robot description parameter file (config/designs/*.yaml)')
    parser.add_argument('--set', action='append', metavar='NAME=VALUE',
                        help='one robot description parameter, e.g. wheel_friction=0.8')
    parser.add_argument('--planner', action='append', metavar='NAME=VALUE',
                        help='one planner parameter, e.g. rear_speed=8.0')
    parser.add_argument('--controller', action='append', metavar='NAME=VALUE',
                        help='one controller parameter, e.g. max_linear_velocity=1.0')
    parser.add_argument('--skip-car-like', action='store_true')
    parser.add_argument('--phi-negative-heights', default='0.04,0.05,0.06,0.07,0.08',
                        type=_height_list,
                        metavar='H1,H2,...',
                        help="[m] then the phi < 0 design's table (semi-active procedure, "
                             'config/designs/phi_negative.yaml, body colliding) at these '
                             "heights; '' skips it")
    parser.add_argument('--write-capability', type=Path, metavar='PATH',
                        help='write the whole-car capability table the planner ships')
    parser.add_argument('--sensor-profiles', default='ideal,realistic',
                        help="the sim's sensors, comma-separated (ideal, realistic, a profile "
                             'YAML): each on the same draws, the first gives the capability')
    args = parser.parse_args(argv)
    robot = _robot(args)
    try:  # every override checked before the first climb
        description = CarDescription.from_values(robot)
        configs = {profile: StackConfig.installed(
            robot=robot, sim={'sensor_profile': profile},
            controller=_assignments(args.controller),
            planner={'capability_file': 'none', **_assignments(args.planner)})
            for profile in args.sensor_profiles.split(',')}
        ranges = RequestRanges(**{item.name: getattr(args, item.name)
                                  for item in fields(RequestRanges)})
    except ValueError as error:
        parser.error(str(error))
    seed = args.seed if args.seed is not None else random.SystemRandom().randrange(2 ** 31)
    started = time.monotonic()
    print(f'swivel car: {args.trials} attempted climbs per height, seed {seed}', flush=True)
    by_profile = {}
    for profile, config in configs.items():
        print(f'sensors: {profile}', flush=True)
        by_profile[profile] = run_swivel(args, config, ranges, seed)
    trials = next(iter(by_profile.values()))
    car_like = {} if args.skip_car_like else run_car_like(args, robot)
    for profile, profile_trials in by_profile.items():
        print(f'\nsensors: {profile}')
        report(profile_trials, car_like, description)
    if len(by_profile) > 1:
        compare_profiles(by_profile)
    if args.phi_negative_heights and not args.write_capability:
        negative = design_values(PHI_NEGATIVE)
        negative_started = time.monotonic()
        print(f'\nphi < 0 design ({PHI_NEGATIVE.name}, semi-active procedure):')
        negative_args = argparse.Namespace(**{**vars(args),
                                              'heights': args.phi_negative_heights})
        negative_config = StackConfig.installed(
            robot={**robot, **negative, 'body_collision': True},
            controller=_assignments(args.controller),
            planner={'capability_file': 'none', **_assignments(args.planner)})
        # Its approach is 0.75-0.94 rad oblique (the minimum approach angle, eqs. 92-100) and
        # turns onto it on wide arcs (plan.semi_active_turn): it needs a far, wide step, or
        # most requests are refused as placed.
        wide = RequestRanges(2.4, 3.0, args.max_yaw, 4.0, 5.0, args.max_offset)
        # Its own draws: the same requests whatever the default robot's table drew.
        report(run_swivel(negative_args, negative_config, wide, seed), {},
               CarDescription.from_values({**robot, **negative}))
        print(f'(phi < 0 table: {time.monotonic() - negative_started:.0f} s wall)')
    if args.write_capability:
        given = sys.argv[1:] if argv is None else argv
        command = 'python -m swivel_car_studies.climb_benchmark ' + shlex.join(
            [*given, *(['--seed', str(seed)] if args.seed is None else [])])
        table = table_of(trials, lambda t: t.four, description, command)
        table.save(args.write_capability, header=(
            'Whole-car climbing capability of the robot description below, measured in physics\n'
            f'through the in-process stack by the command below (seed {seed}):\n'
            f'  {command}\n'
            "Success: all four wheels on top, level, at rest (the sim's ground truth). The\n"
            f'planner refuses steps above its limit, {STATISTIC}:\n'
            f'{table.limit:.3f} m.'))
        print(f'wrote {args.write_capability}: whole-car limit {table.limit:.3f} m')
    print(f'({time.monotonic() - started:.0f} s wall)')


if __name__ == '__main__':
    main()
