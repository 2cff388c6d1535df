"""Step-climbing benchmark in the real sim: ``python -m swivel_car_planner.benchmark``.

Climbs steps from 2 cm to beyond the model's maximum scalable step in 1 cm increments, each
from several seeded random approach distances and headings, through the real stack
(sim_node in lockstep, controller_node, odometry_node, planner_node), and prints a success
table judged by the sim's ground truth: the front axle on top (the thesis' criterion, III:
"when [the front wheels are above the step] we can assume the mobile platform has overcome
the step") and all four wheels on top. Then the car-like baseline (sim robot_variant
car_like) driven straight at the same steps. Takes about 15 s of wall time per climb; use
``--trials``, ``--max-height`` and ``--step`` for a shorter run. Not part of the tests.
"""

from __future__ import annotations

import argparse
from collections import defaultdict
from dataclasses import dataclass
import random
import time

from pathlib import Path
import shlex
import sys

from swivel_car_model import kinematics
from swivel_car_model.description import CarDescription
from swivel_car_model.params import SwivelCarParams

from swivel_car_planner.core import ErrorCode
from swivel_car_planner.core.capability import (
    CapabilityTable, description_values, RELIABLE)
from swivel_car_planner.sim_session import SimSession

# Refusals that say the request cannot be climbed from where it stands, not how high the car
# climbs: such trials are reported, not counted.
_NOT_ATTEMPTED = (ErrorCode.INVALID_REQUEST,)


@dataclass(frozen=True)
class Trial:
    height: float  # [m]
    distance: float  # [m]
    yaw: float  # [rad]
    width: float  # [m]
    code: int
    front: bool
    four: bool
    peak_torque: float  # [N m] measured (controller's commanded torque)
    energy: float  # [J] measured
    predicted_torque: float  # [N m] model
    predicted_energy: float  # [J] model
    duration: float  # [s] sim time


def heights(start: float, stop: float, step: float) -> list[float]:
    count = int(round((stop - start) / step))
    return [round(start + i * step, 4) for i in range(count + 1)]


def run_swivel(args: argparse.Namespace, rng: random.Random) -> list[Trial]:
    # Without the capability table, so that the front's reach is measured too.
    session = SimSession(planner_parameters={'capability_file': 'none'})
    trials = []
    try:
        session.wait_ready()
        for height in heights(args.min_height, args.max_height, args.step):
            for _ in range(args.trials):
                distance = rng.uniform(args.min_distance, args.max_distance)
                yaw = rng.uniform(-0.3, 0.3)
                width = rng.uniform(0.8, 2.0)
                session.reset()
                session.spawn_step(height, distance, yaw, width=width)
                response = session.climb(height, distance, yaw, width=width)
                session.settle(0.3)
                trial = Trial(height, distance, yaw, width, response.error_code,
                              session.front_on_top(height), session.four_wheels_on_top(height),
                              response.outcome.peak_torque, response.outcome.energy,
                              response.plan.peak_torque, response.plan.energy,
                              response.outcome.duration)
                trials.append(trial)
                print(f'  {height:.2f} m  d {distance:.2f} m  yaw {yaw:+.2f} rad  width '
                      f'{width:.2f} m: '
                      f'{ErrorCode(trial.code).name:<18} front {"up" if trial.front else "--"}'
                      f'  four {"up" if trial.four else "--"}  ({response.message})',
                      flush=True)
    finally:
        session.close()
    return trials


def run_car_like(args: argparse.Namespace) -> dict[float, bool]:
    """Drive the car-like baseline straight at each step; True where it ends on top."""
    session = SimSession(robot_variant='car_like', planner=False)
    results = {}
    try:
        session.wait_ready()
        for height in heights(args.min_height, args.max_height, args.step):
            session.reset()
            session.spawn_step(height, 0.3, depth=10.0)  # deep: it must not drive off the far side
            session.drive_straight(6.5, args.car_like_seconds)
            results[height] = session.four_wheels_on_top(height)
            print(f'  car-like {height:.2f} m: {"on top" if results[height] else "stopped"}',
                  flush=True)
            if not results[height] and height > 0.05:
                break  # higher steps only fail the more
    finally:
        session.close()
    return results


def table_of(trials: list[Trial], judge, command: str) -> CapabilityTable:
    """Success of the attempted climbs by height, judged by ``judge(trial)``."""
    by_height: dict[float, list[Trial]] = defaultdict(list)
    for trial in trials:
        if trial.code not in _NOT_ATTEMPTED:
            by_height[trial.height].append(trial)
    heights = sorted(h for h, group in by_height.items() if group)
    return CapabilityTable(
        tuple(heights), tuple(len(by_height[h]) for h in heights),
        tuple(sum(bool(judge(t)) for t in by_height[h]) for h in heights),
        description_values(CarDescription()), command=command)


def highest(trials: list[Trial], judge) -> float:
    """Highest height of the unbroken run of reliable heights from the lowest. # [m]"""
    return table_of(trials, judge, '').limit if trials else 0.0


def report(trials: list[Trial], car_like: dict[float, bool], p: SwivelCarParams) -> None:
    by_height: dict[float, list[Trial]] = defaultdict(list)
    for trial in trials:
        by_height[trial.height].append(trial)
    print()
    print(' height | n | refused | front up | 4 wheels | peak torque meas / model | energy meas '
          '/ model | car-like | typical failure')
    print('--------|---|---------|----------|----------|-------------------------|-------------'
          '---------|----------|----------------')
    for height, all_trials in sorted(by_height.items()):
        group = [t for t in all_trials if t.code not in _NOT_ATTEMPTED]
        refused = len(all_trials) - len(group)
        n = len(group)
        if n == 0:
            print(f' {height:.2f} m | 0 | {refused:7d} | every request refused as too close')
            continue
        front_rate = sum(t.front for t in group) / n
        four_rate = sum(t.four for t in group) / n
        climbed = [t for t in group if t.code not in (
            ErrorCode.UNREACHABLE_HEIGHT, ErrorCode.TIP_OVER, ErrorCode.TORQUE_LIMIT,
            ErrorCode.WHEEL_INTERFERENCE, ErrorCode.INVALID_REQUEST)]
        torque = (f'{max(t.peak_torque for t in climbed):5.1f} / '
                  f'{climbed[0].predicted_torque:5.1f} N m') if climbed else '  refused'
        energy = (f'{sum(t.energy for t in climbed) / len(climbed):5.1f} / '
                  f'{climbed[0].predicted_energy:5.1f} J') if climbed else '  refused'
        failures = [ErrorCode(t.code).name for t in group if not t.four]
        typical = max(set(failures), key=failures.count) if failures else '-'
        car = {True: 'on top', False: 'stopped', None: '-'}[car_like.get(height)]
        print(f' {height:.2f} m | {n} | {refused:7d} | {front_rate:6.0%}   | {four_rate:6.0%}'
              f'   | {torque:>23} | {energy:>20} | {car:8} | {typical}')
    model_max, _ = kinematics.max_scalable_step(p, respect_tip_over=True)
    front_best = highest(trials, lambda t: t.front)
    four_best = highest(trials, lambda t: t.four)
    car_best = max((h for h, ok in car_like.items() if ok), default=0.0)
    print()
    print(f'model max scalable step (tip-over rule kept): {model_max:.3f} m = '
          f'{model_max / p.r:.2f} r')
    print(f'highest step climbed reliably (>= {RELIABLE:.0%}), front axle on top: '
          f'{front_best:.2f} m = {front_best / model_max:.0%} of the model limit')
    print(f'highest step climbed reliably (>= {RELIABLE:.0%}), all four wheels on top: '
          f'{four_best:.2f} m = {four_best / model_max:.0%} of the model limit')
    print(f'car-like baseline, highest step climbed (four wheels): {car_best:.2f} m = '
          f'{car_best / p.r:.2f} r (thesis: below one wheel radius)')


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p = CarDescription().model_params()
    model_max, _ = kinematics.max_scalable_step(p)
    parser.add_argument('--min-height', type=float, default=0.02, help='[m]')
    parser.add_argument('--max-height', type=float, default=round(model_max + 0.02, 2),
                        help='[m], default 2 cm beyond the model limit')
    parser.add_argument('--step', type=float, default=0.01, help='[m]')
    parser.add_argument('--trials', type=int, default=3, help='approaches per height')
    parser.add_argument('--seed', type=int, default=1)
    parser.add_argument('--car-like-seconds', type=float, default=6.0,
                        help='[s] sim time the baseline drives at each step')
    parser.add_argument('--skip-car-like', action='store_true')
    parser.add_argument('--min-distance', type=float, default=1.0,
                        help='[m] nearest step edge drawn (nearer ones are refused as too '
                             'close to align)')
    parser.add_argument('--max-distance', type=float, default=1.6, help='[m]')
    parser.add_argument('--write-capability', type=Path, metavar='PATH',
                        help='write the whole-car capability table the planner ships '
                             '(swivel_car_planner/config/capability.yaml)')
    args = parser.parse_args(argv)
    rng = random.Random(args.seed)
    started = time.monotonic()
    print(f'swivel car: {args.trials} approaches per height, seed {args.seed}')
    trials = run_swivel(args, rng)
    car_like = {} if args.skip_car_like else run_car_like(args)
    report(trials, car_like, p)
    if args.write_capability:
        command = 'python -m swivel_car_planner.benchmark ' + shlex.join(sys.argv[1:])
        table = table_of(trials, lambda t: t.four, command)
        table.save(args.write_capability, header=(
            'Whole-car climbing capability of the default robot description, measured in the\n'
            'sim through the ROS stack; regenerate with the command below. The planner refuses\n'
            'steps above the highest height climbed reliably.'))
        print(f'wrote {args.write_capability}: whole-car limit {table.limit:.3f} m')
    print(f'({time.monotonic() - started:.0f} s wall)')


if __name__ == '__main__':
    main()
