"""
Climbs on a detected step beside climbs on the given step, on the same draws.

``python -m swivel_car_studies.detected_climb_benchmark [--heights 0.02,...] [--trials 8]``.
The climb benchmark's randomised requests (``climb_benchmark.RequestRanges``; each height's
draws from its own seed, as the climb benchmark's default run draws them, so a height run
alone or in a process of its own climbs the same steps): each draw is climbed twice through
the in-process stack, from the same start: once told the step (the climb benchmark's column,
without the camera), once with ``use_detected_step`` (the sim's depth camera with its noise,
the step detector and its fusion started afresh, the planner taking the latest detection).
Draws the planner refuses as placed when told the step (no room) are drawn again, as the climb
benchmark does. Judged by the sim's ground truth: all four wheels on top. Each detected
climb's line shows the detection it started from beside the true step. Prints, asserts
nothing.
"""

from __future__ import annotations

import argparse
import random

from swivel_car_planner.core import ClimbRequest, ErrorCode
from swivel_car_studies.climb_benchmark import climb_trial, heights as height_range
from swivel_car_studies.climb_benchmark import RequestRanges
from swivel_car_studies.inprocess import InProcessStack

DEFAULT_HEIGHTS = (0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08)  # [m] up to past the limit
SEE_TIME = 0.3  # [s] the camera's three frames of the new step before the climb is asked
# The climb benchmark's default heights: the n-th of them draws from seed * 1000 + n.
CLIMB_BENCHMARK_HEIGHTS = height_range(0.02, 0.20, 0.01)  # [m]


def height_seed(seed: int, height: float) -> int:
    """Return the seed of ``height``'s draws in the climb benchmark's default run."""
    steps = [abs(height - h) for h in CLIMB_BENCHMARK_HEIGHTS]
    index = steps.index(min(steps))
    if steps[index] > 1e-6:  # not one of them: a seed of its own, after theirs
        index = len(CLIMB_BENCHMARK_HEIGHTS) + round(height * 1e4)
    return seed * 1000 + index


def detected_trial(stack: InProcessStack, height: float, distance: float, yaw: float,
                   width: float) -> tuple[ErrorCode, str, bool, str]:
    """
    Climb a step spawned as the climb benchmark's, the planner told nothing about it.

    Returns the climb's code and message, all four wheels on top, and what the planner's
    detection said when the climb was asked, in one line.
    """
    stack.settle(0.2)
    stack.spawn_step(height, distance, yaw, width=width, depth=3.0)
    stack.settle(SEE_TIME)
    seen, _ = stack.detection.planner.fresh(stack.time)
    said = ('none' if seen is None else
            f'h {seen.height * 100:.2f} cm  d {seen.distance:.3f} m  yaw {seen.yaw:+.3f} rad')
    result = stack.climb(ClimbRequest(0.0, 0.0, 0.0), use_detected_step=True)
    stack.settle(1.0)
    return result.error_code, result.message, stack.four_wheels_on_top(height), said


def run(heights: list[float], trials: int, seed: int, max_draws: int) -> None:
    """Climb, print each pair and the table."""
    ranges = RequestRanges()
    table = []
    with InProcessStack() as stack:
        for height in heights:
            rng = random.Random(height_seed(seed, height))
            given = detected = refused = attempted = drawn = 0
            while attempted < trials and drawn < trials * max_draws:
                drawn += 1
                distance, yaw, width, offset = ranges.draw(rng)
                stack.reset()
                stack.detection = None  # told: no camera, as the climb benchmark climbs
                told = climb_trial(stack, height, distance, yaw, width, offset)
                if told.code == ErrorCode.INVALID_REQUEST:
                    continue
                attempted += 1
                given += told.four
                stack.reset()
                stack.enable_detection(seed)  # a fresh camera and detector, as reset's nodes
                code, message, four, said = detected_trial(stack, height, distance, yaw,
                                                           width)
                detected += four
                refused += code == ErrorCode.NO_STEP_DETECTED
                print(f'  {height:.2f} m  d {distance:.2f} m  yaw {yaw:+.2f} rad  width '
                      f'{width:.2f} m: told {"up" if told.four else "--"} '
                      f'({told.code.name}), detected {"up" if four else "--"} ({code.name}: '
                      f'{message}; detected {said})', flush=True)
            table.append((height, attempted, given, detected, refused))
    print(f'\nAll four wheels on top, the same draws told and detected (seed {seed}, '
          f'{trials} attempted climbs per height):')
    print('| height | told the step | detected step | detected refused (no step) |')
    print('|---|---|---|---|')
    for height, attempted, given, detected, refused in table:
        print(f'| {height * 100:.0f} cm | {given}/{attempted} | {detected}/{attempted} | '
              f'{refused} |')


def main(argv: list[str] | None = None) -> None:
    """Run from the command line."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--heights', default=','.join(f'{h:g}' for h in DEFAULT_HEIGHTS),
                        help='[m] comma-separated step heights')
    parser.add_argument('--trials', type=int, default=8, help='attempted climbs per height')
    parser.add_argument('--seed', type=int, default=1,
                        help="seed of the draws (the climb benchmark's) and the noise")
    parser.add_argument('--max-draws', type=int, default=4,
                        help='draws per attempted climb before a height gives up')
    args = parser.parse_args(argv)
    try:
        heights = [float(text) for text in args.heights.split(',')]
    except ValueError:
        parser.error(f'--heights must be numbers, got {args.heights!r}')
    if args.trials < 1 or any(not 0.0 < h < 1.0 for h in heights):
        parser.error('--trials must be >= 1 and every height in (0, 1) m')
    run(heights, args.trials, args.seed, args.max_draws)


if __name__ == '__main__':
    main()
