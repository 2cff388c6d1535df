"""
In-process stack benchmark: one climb of a step.

Measures its real-time factor (target: 50x) beside raw pybullet stepping of the same robot, per
CPU second of this process too (which does not depend on what else runs on the machine), and
each core's cost per control period.

    python -m swivel_car_studies.benchmark [--height 0.04] [--distance 1.0]

Prints; asserts nothing. The per-core figures include the ROS-free adapters the nodes use
(joint reading, the odometry's publish schedule); ``sim`` is one control period of physics
(``steps_per_period`` pybullet steps with the drive train).
"""

from __future__ import annotations

import argparse
import time

from swivel_car_planner.core import ClimbRequest, make_plan
from swivel_car_sim.benchmark import raw_pybullet_rtf
from swivel_car_studies.inprocess import InProcessStack

_TARGET_RTF = 50.0  # [1] the in-process stack during a climb (issue 14)

_CORES = (('controller', 'SwivelController.step (JointStateController.answer)'),
          ('odometry', 'OffsetTricycleOdometry.update (JointStateOdometry.update)'),
          ('state_machine', 'ClimbStateMachine.update'),
          ('sim', 'SwivelCarSim.step, one control period'))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--height', type=float, default=0.04, help='step height [m]')
    parser.add_argument('--distance', type=float, default=1.0,
                        help='front axle to the edge [m]')
    args = parser.parse_args(argv)
    request = ClimbRequest(args.height, args.distance, 0.0)
    with InProcessStack() as plain:
        plain.spawn_step(args.height, args.distance)
        planning = time.perf_counter()
        make_plan(plain.car, plain.config.planner, request)
        planning = time.perf_counter() - planning
        wall, cpu = time.perf_counter(), time.process_time()
        result = plain.climb(request)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    sim_time = result.outcome.duration if result.outcome else 0.0
    print(f'climb of a {args.height:.3f} m step {args.distance:.2f} m ahead: '
          f'{result.error_code.name} ({result.message})')
    print(f"  first plan in the process {planning:.2f} s (fills the model's caches; later "
          f'plans reuse them)')
    raw = raw_pybullet_rtf(3.0)
    print(f'  climb: sim time {sim_time:.2f} s, wall {wall:.2f} s, real-time factor '
          f'{sim_time / wall:.1f}x (cpu {sim_time / cpu:.1f}x; target >= {_TARGET_RTF:.0f}x)')
    print(f'  raw pybullet stepSimulation of the same robot: {raw[0]:.1f}x (cpu {raw[1]:.1f}x); '
          f'the stack runs at {sim_time / cpu / raw[1]:.0%} of it per CPU second')
    with InProcessStack(profile=True) as profiled:
        profiled.spawn_step(args.height, args.distance)
        profiled.climb(ClimbRequest(args.height, args.distance, 0.0))
        timings = profiled.timings
    print('per control period (10 ms of sim time), mean over the climb:')
    for name, what in _CORES:
        total, count = timings.get(name, (0.0, 0))
        mean = total / count * 1e6 if count else float('nan')
        print(f'  {name:14s} {mean:8.1f} us   {what}')


if __name__ == '__main__':
    main()
