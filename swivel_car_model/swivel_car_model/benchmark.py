"""
Timings of the model library, a benchmark and not a test.

``python -m swivel_car_model.benchmark``

Prints, each against its target: kinematics for 100,000 swivel angles (< 50 ms), one
inverse-steering call (< 20 us), the 31.5 s nonholonomic DAE run (< 2 s) and all figures
(< 30 s), as wall and process CPU time (the verdict uses the CPU time, which a busy machine
does not inflate). Best of several repetitions; caches are warmed first where the library
keeps them.
"""

from __future__ import annotations

import math
from pathlib import Path
import tempfile
import time
from typing import Callable

import numpy as np

from swivel_car_model import dynamics, figures, kinematics
from swivel_car_model.params import SwivelCarParams


def best_of(func: Callable[[], object], repeat: int) -> tuple[float, float]:
    """
    Return the smallest wall time and smallest process CPU time of ``repeat`` calls [s].

    The CPU time is what to compare on a busy machine: the wall time includes waiting for the
    cores.
    """
    wall = cpu = math.inf
    for _ in range(repeat):
        start, start_cpu = time.perf_counter(), time.process_time()
        func()
        wall = min(wall, time.perf_counter() - start)
        cpu = min(cpu, time.process_time() - start_cpu)
    return wall, cpu


def main() -> None:
    p = SwivelCarParams()
    angles = np.random.default_rng(0).uniform(-p.max_swivel_angle, p.max_swivel_angle, 100_000)
    kinematics.kinematic_state(p, angles[:10])
    kinematics.swivel_for_steering(p, 0.3)
    rows = []
    rows.append(('kinematics (lift, steering, contact, clearance) for 100,000 angles',
                 best_of(lambda: kinematics.kinematic_state(p, angles), 5), 0.050))
    calls = 10_000
    wall, cpu = best_of(lambda: [kinematics.swivel_for_steering(p, 0.3) for _ in range(calls)],
                        3)
    rows.append(('one swivel_for_steering call', (wall / calls, cpu / calls), 20e-6))
    rows.append(('nonholonomic DAE, theta2 0 -> pi/2 at 0.05 rad/s (31.5 s)',
                 best_of(lambda: dynamics.simulate_planar_swivel(p), 2), 2.0))
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        rows.append(('all figures (24 PNG files)',
                     best_of(lambda: figures.main(['--out', str(out / 'figures'),
                                                   '--doc', str(out / 'table.md')]), 1), 30.0))
    width = max(len(name) for name, _, _ in rows)
    print(f'{"":<{width}}  {"wall":>10}  {"cpu":>10}')
    for name, (wall, cpu), target in rows:
        verdict = 'ok' if cpu < target else 'SLOW'
        print(f'{name:<{width}}  {_fmt(wall):>10}  {_fmt(cpu):>10}  (target < {_fmt(target)})  '
              f'{verdict}')


def _fmt(seconds: float) -> str:
    if seconds < 1e-3:
        return f'{seconds * 1e6:.1f} us'
    if seconds < 1.0:
        return f'{seconds * 1e3:.1f} ms'
    return f'{seconds:.2f} s'


if __name__ == '__main__':
    main()
