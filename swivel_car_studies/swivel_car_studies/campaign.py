"""
Design campaigns: climbs of a grid of robot designs and procedures, in parallel on Ray.

    python -m swivel_car_studies.campaign SWEEP.yaml --out results.csv [--workers N]
        [--address ADDR]

(``ros2 run swivel_car_studies campaign ...`` on a full install.) The sweep file::

    design:            # CarDescription fields: a value, or a list of values to sweep
      body_offset: [0.0, 0.05]
      rear_differential: [open, locked]
    procedure:         # PlannerConfig fields, the same way
      rear_speed: 6.5
    trials:
      heights: [0.06, 0.08]     # [m]
      count: 4                  # trials per design point and height
      seed: 1
      min_distance: 0.2         # and the other RequestRanges fields of climb_benchmark
      max_yaw: 0.3

Every combination of the listed values (the grid product) is a design point; each runs
``count`` trials at every height. Trial ``i`` at height ``h`` draws its request (distance,
yaw, width, offset) from the seed, ``h`` and ``i`` alone, so every design point meets the same
requests, and growing ``count`` or ``heights`` later only adds trials. The planner is given no
capability table (``capability_file: none``), as climb_benchmark measures: it tries every
height.

The whole sweep is validated before Ray starts, by the robot description, the planner
configuration and the planner's request check themselves: a bad file ends with one line
naming the field, exit code 2. Each trial runs ``climb_benchmark.climb_trial`` in a fresh
``InProcessStack``, so no trial depends on another's history. One CSV row per trial is
appended as it finishes: the trial (height [m], trial index, seed, distance [m], yaw [rad],
width [m], offset [m]), the full configuration (``design.<field>``, ``procedure.<field>``),
the result judged by the sim's ground truth (``front_on_top``, ``four_wheels_on_top``; the
planner's ``success``, ``error_code``, ``message``; ``peak_torque`` [N m], ``energy`` [J],
``duration`` [s] of sim time, ``wall`` [s]), the Ray node it ran on and the git revision of
this checkout. Run the same command again after an interruption: the trials already in the
file (same trial and configuration) are skipped; a changed default of the description or the
planner makes another configuration, whose trials run anew. A trial that raises is reported
on stderr and not written (exit code 1), so the next run retries it.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable, Iterator
import contextlib
import csv
from dataclasses import asdict, dataclass, fields, replace
import itertools
import logging
import os
from pathlib import Path
import random
import subprocess
import sys
import time
from typing import Any, TextIO

from swivel_car_model.description import CarDescription
from swivel_car_planner.core import ClimbRequest, ErrorCode, PlannerConfig, validate_request
from swivel_car_studies.climb_benchmark import climb_trial, RequestRanges, Trial
from swivel_car_studies.inprocess import InProcessStack, StackConfig
import yaml

_SECTIONS = ('design', 'procedure', 'trials')
TRIAL_COLUMNS = ('height', 'trial', 'seed', 'distance', 'yaw', 'width', 'offset')
# The result columns: climb_benchmark.Trial's fields but the request's (trial columns), some
# renamed to say what they are in a table of their own.
_RESULT_COLUMNS = {item.name: {'code': 'error_code', 'front': 'front_on_top',
                               'four': 'four_wheels_on_top'}.get(item.name, item.name)
                   for item in fields(Trial) if item.name not in TRIAL_COLUMNS}
_RUN_COLUMNS = ('wall', 'ray_node', 'git_revision')
# Ray: the workers' output (pybullet's banner) kept from the driver, failures come back as
# exceptions; a local instance without a dashboard and with a small object store (a trial's
# spec and row are a few kB).
_RAY_OPTIONS = {'log_to_driver': False, 'logging_level': logging.WARNING}
_LOCAL_RAY_OPTIONS = {'include_dashboard': False, 'object_store_memory': 200 * 10 ** 6}


class SweepError(ValueError):
    """A sweep file the campaign refuses; the message names the field."""


@dataclass(frozen=True)
class Sweep:
    """A sweep file's contents, each swept field as the tuple of its values."""

    design: dict[str, tuple]
    procedure: dict[str, tuple]
    heights: tuple[float, ...]  # [m]
    count: int
    seed: int
    ranges: RequestRanges


@dataclass(frozen=True)
class TrialSpec:
    """One trial: a design point's complete configuration and one drawn request."""

    config: StackConfig
    point: tuple[tuple[str, Any], ...]  # the swept fields' values, for progress lines
    height: float  # [m]
    trial: int
    seed: int
    distance: float  # [m]
    yaw: float  # [rad]
    width: float  # [m]
    offset: float  # [m]

    def columns(self) -> dict[str, str]:
        """Return the trial and its full configuration as CSV cells: the key of its row."""
        cells = {name: getattr(self, name) for name in TRIAL_COLUMNS}
        cells.update({f'design.{k}': v for k, v in asdict(self.config.robot).items()})
        cells.update({f'procedure.{k}': v for k, v in asdict(self.config.planner).items()})
        return {name: _cell(value) for name, value in cells.items()}

    def key(self) -> tuple[str, ...]:
        """Return what makes two rows the same trial: the cells of ``columns``."""
        return tuple(self.columns().values())

    def label(self) -> str:
        swept = ' '.join(f'{name}={value}' for name, value in self.point)
        return f'{swept + " | " if swept else ""}{self.height:.3f} m #{self.trial}'


def _cell(value: Any) -> str:
    """Format a CSV cell: a float reads back as the same float, an enum member is its name."""
    return value.name if isinstance(value, ErrorCode) else str(value)


def _floats(values: dict[str, Any]) -> dict[str, Any]:
    """Turn an integer where a number is due into that float (as the nodes take it)."""
    return {name: float(value) if isinstance(value, int) and not isinstance(value, bool)
            else value for name, value in values.items()}


def key_columns() -> list[str]:
    """Return the columns that make two rows the same trial: the trial and its configuration."""
    return ([*TRIAL_COLUMNS]
            + [f'design.{item.name}' for item in fields(CarDescription)]
            + [f'procedure.{item.name}' for item in fields(PlannerConfig)])


def columns() -> list[str]:
    """Return the CSV header."""
    return key_columns() + list(_RESULT_COLUMNS.values()) + list(_RUN_COLUMNS)


# --- the sweep file -------------------------------------------------------------------------

def _mapping(data: Any, where: str) -> dict:
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise SweepError(f'{where} must be a mapping of field: value, got {data!r}')
    return dict(data)


def _swept(data: Any, section: str) -> dict[str, tuple]:
    swept = {}
    for name, value in _mapping(data, section).items():
        values = tuple(value) if isinstance(value, list) else (value,)
        if not values:
            raise SweepError(f'{section}.{name}: an empty list sweeps nothing')
        swept[str(name)] = values
    return swept


def _integer(trials: dict, name: str, default: int, minimum: int | None = None) -> int:
    value = trials.pop(name, default)
    if isinstance(value, bool) or not isinstance(value, int) \
            or (minimum is not None and value < minimum):
        bound = f' >= {minimum}' if minimum is not None else ''
        raise SweepError(f'trials.{name} must be an integer{bound}, got {value!r}')
    return value


def parse_sweep(data: Any) -> Sweep:
    """
    Parse a sweep from a sweep file's YAML data (module docstring).

    Raises
    ------
    SweepError
        An unknown section or field, a value of the wrong kind, an empty sweep.

    """
    data = _mapping(data, 'the sweep file')
    unknown = sorted(set(data) - set(_SECTIONS))
    if unknown:
        raise SweepError(f'unknown section(s) {", ".join(map(str, unknown))}; known: '
                         f'{", ".join(_SECTIONS)}')
    trials = _mapping(data.get('trials'), 'trials')
    heights = trials.pop('heights', None)
    if not isinstance(heights, list) or not heights or not all(
            isinstance(h, (int, float)) and not isinstance(h, bool) for h in heights):
        raise SweepError(f'trials.heights must be a non-empty list of step heights [m], got '
                         f'{heights!r}')
    count = _integer(trials, 'count', 1, minimum=1)
    seed = _integer(trials, 'seed', 1)
    known = {item.name for item in fields(RequestRanges)}
    unknown = sorted(set(trials) - known)
    if unknown:
        raise SweepError(f'unknown trials field(s) {", ".join(map(str, unknown))}; known: '
                         f'heights, count, seed, {", ".join(sorted(known))}')
    try:
        ranges = RequestRanges(**trials)
    except ValueError as error:
        raise SweepError(f'trials.{error}') from None
    procedure = _swept(data.get('procedure'), 'procedure')
    unknown = sorted(set(procedure) - {item.name for item in fields(PlannerConfig)})
    if unknown:
        raise SweepError(f'unknown procedure field(s) {", ".join(unknown)} (PlannerConfig '
                         f'fields)')
    return Sweep(_swept(data.get('design'), 'design'), procedure,
                 tuple(float(h) for h in heights), count, seed, ranges)


def load_sweep(path: str | Path) -> Sweep:
    """
    ``parse_sweep`` of a file.

    Raises
    ------
    SweepError
        Also for a file that cannot be read or is not YAML.

    """
    try:
        data = yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as error:
        raise SweepError(f'cannot read the sweep file {path}: '
                         f'{" ".join(str(error).split())}') from None
    return parse_sweep(data)


def _points(swept: dict[str, tuple]) -> list[dict[str, Any]]:
    return [dict(zip(swept, values)) for values in itertools.product(*swept.values())]


def _text(point: dict[str, Any]) -> str:
    return ', '.join(f'{name}={value!r}' for name, value in point.items())


def plan_trials(sweep: Sweep) -> list[TrialSpec]:
    """
    Plan every trial of the sweep, design point by design point.

    Each configuration and request is validated by the description, the planner's
    configuration and its request check.

    Raises
    ------
    SweepError
        A design or procedure point, or a drawn request, those refuse; the message names the
        field. Or the grid repeats a trial (a value listed twice).

    """
    draws = {(height, index): sweep.ranges.draw(
        random.Random(f'{sweep.seed}:{height!r}:{index}'))
        for height in sweep.heights for index in range(sweep.count)}
    swept_names = [name for name, values in {**sweep.design, **sweep.procedure}.items()
                   if len(values) > 1]
    trials, keys = [], set()
    for design in _points(sweep.design):
        try:
            CarDescription.from_values(design)  # StackConfig also takes the sim's names
            base = StackConfig.installed(robot=design, planner={'capability_file': 'none'})
        except ValueError as error:
            raise SweepError(f'design {_text(design)}: {error}') from None
        for procedure in _points(sweep.procedure):
            try:
                config = replace(base, planner=replace(base.planner, **_floats(procedure)))
            except ValueError as error:
                raise SweepError(f'procedure {_text(procedure)}: {error}') from None
            for height in sweep.heights:
                for distance, yaw, width, offset in sweep.ranges.bounds():
                    code, message = validate_request(ClimbRequest(
                        step_height=height, step_distance=distance, step_yaw=yaw,
                        step_width=width, step_offset=offset), config.planner)
                    if code != ErrorCode.NONE:
                        raise SweepError(f"trials (height {height!r} m, the ranges' "
                                         f'bounds): {message}')
            point = tuple((name, {**design, **procedure}[name]) for name in swept_names)
            for (height, index), (distance, yaw, width, offset) in draws.items():
                spec = TrialSpec(config, point, height, index, sweep.seed, distance,
                                 yaw, width, offset)
                key = spec.key()
                if key in keys:
                    raise SweepError(f'the grid repeats a trial: a value listed twice in '
                                     f'design {_text(design)} or procedure {_text(procedure)}')
                keys.add(key)
                trials.append(spec)
    return trials


# --- one trial (on a Ray worker) ------------------------------------------------------------

def result_cells(trial: Trial, wall: float) -> dict[str, str]:
    """Return the result columns of a climbed trial that took ``wall`` [s]."""
    cells = {column: _cell(getattr(trial, name)) for name, column in _RESULT_COLUMNS.items()}
    cells['message'] = ' '.join(trial.message.split())  # one row, one line
    cells['wall'] = _cell(wall)
    return cells


def run_trial(spec: TrialSpec) -> dict[str, str]:
    """Climb one trial in a fresh in-process stack; its result columns."""
    started = time.perf_counter()
    with InProcessStack(config=spec.config) as stack:
        trial = climb_trial(stack, spec.height, spec.distance, spec.yaw, spec.width,
                            spec.offset)
    return result_cells(trial, time.perf_counter() - started)


def _run_on_worker(spec: TrialSpec) -> dict[str, str]:
    import ray  # here, not above: checking a sweep, and the nodes, never wait for its import
    return {**run_trial(spec), 'ray_node': ray.get_runtime_context().get_node_id()}


@contextlib.contextmanager
def ray_session(workers: int | None, address: str | None) -> Iterator[int]:
    """
    Start Ray, local (``workers`` CPUs, default all), or join it at ``address``.

    Yields how many trials run at once.
    """
    import ray
    if address:
        ray.init(address=address, **_RAY_OPTIONS)
    else:
        ray.init(address='local', num_cpus=workers or os.cpu_count(), **_RAY_OPTIONS,
                 **_LOCAL_RAY_OPTIONS)
    try:
        cpus = int(ray.cluster_resources().get('CPU', 1))
        yield min(workers, cpus) if workers else cpus
    finally:
        ray.shutdown()


def ray_results(trials: list[TrialSpec], at_once: int
                ) -> Iterator[tuple[TrialSpec, dict[str, str] | Exception]]:
    """
    Run ``trials`` on the connected Ray, at most ``at_once`` at a time.

    Two are queued per CPU, so none idles between trials. Yields each with its result
    columns, or the exception it raised, as it finishes.
    """
    import ray
    remote = ray.remote(num_cpus=1)(_run_on_worker)
    queue, running = list(reversed(trials)), {}
    while queue or running:
        while queue and len(running) < 2 * at_once:
            spec = queue.pop()
            running[remote.remote(spec)] = spec
        done, _ = ray.wait(list(running), num_returns=1, timeout=1.0)
        for ref in done:
            spec = running.pop(ref)
            try:
                yield spec, ray.get(ref)
            except ray.exceptions.RayError as error:
                yield spec, error


# --- the results file -----------------------------------------------------------------------

def finished_keys(out: Path) -> set[tuple[str, ...]]:
    """
    Return the keys of the trials in ``out`` (none if it does not exist).

    A last row cut short (the campaign killed while writing it) is removed from the file.

    Raises
    ------
    SweepError
        ``out`` has other columns than this campaign writes.

    """
    if not out.exists():
        return set()
    with out.open('rb+') as raw:
        data = raw.read()
        if data and not data.endswith(b'\n'):
            raw.truncate(data.rfind(b'\n') + 1)
    with out.open(newline='') as file:
        rows = list(csv.reader(file))
    if not rows:
        return set()
    header = columns()
    if rows[0] != header:
        raise SweepError(f'{out} has other columns than this campaign writes (another '
                         f'campaign, or an older version of it): give another --out')
    key = len(key_columns())
    return {tuple(row[:key]) for row in rows[1:] if len(row) == len(header)}


def git_revision() -> str:
    """Return this checkout's commit, '+dirty' with uncommitted changes; 'unknown' outside git."""
    here = Path(__file__).resolve().parent
    try:
        head = subprocess.run(['git', 'rev-parse', 'HEAD'], cwd=here, capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(['git', '--no-optional-locks', 'diff', '--quiet', 'HEAD'],
                               cwd=here, capture_output=True).returncode != 0
    except (OSError, subprocess.CalledProcessError):
        return 'unknown'
    return head + ('+dirty' if dirty else '')


def record(results: Iterable[tuple[TrialSpec, dict[str, str] | Exception]], out: Path,
           total: int, progress: TextIO | None = None) -> int:
    """
    Append a row to ``out`` for each finished trial, flushed at once.

    The header goes first into a new file; a progress line for each trial goes to
    ``progress`` (default stderr). Returns how many raised.
    """
    progress = progress or sys.stderr
    header, revision = columns(), git_revision()
    new = not out.exists() or out.stat().st_size == 0
    failed = done = 0
    started = time.monotonic()
    with out.open('a', newline='') as file:
        writer = csv.DictWriter(file, header)
        if new:
            writer.writeheader()
            file.flush()
        for spec, result in results:
            done += 1
            rate = done / max(time.monotonic() - started, 1e-9) * 60.0  # [trials/min]
            head = f'[{done}/{total}] {rate:.1f}/min, {(total - done) / rate:.0f} min left |'
            if isinstance(result, Exception):
                failed += 1
                print(f'{head} {spec.label()}: RAISED, not written: '
                      f'{" ".join(str(result).split())[-300:]}', file=progress, flush=True)
                continue
            writer.writerow({**spec.columns(), **result, 'git_revision': revision})
            file.flush()
            print(f'{head} {spec.label()}: {result["error_code"]}, front '
                  f'{"up" if result["front_on_top"] == "True" else "--"}, four '
                  f'{"up" if result["four_wheels_on_top"] == "True" else "--"} '
                  f'({float(result["wall"]):.1f} s)', file=progress, flush=True)
    return failed


# --- the command ----------------------------------------------------------------------------

def _refuse(message: str) -> None:
    print(f'campaign: error: {message}', file=sys.stderr)
    sys.exit(2)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog='campaign', description=__doc__.split('\n\n')[0])
    parser.add_argument('sweep', type=Path, help='the sweep file (YAML)')
    parser.add_argument('--out', type=Path, required=True,
                        help='results CSV: appended to, trials already in it are skipped')
    parser.add_argument('--workers', type=int, default=None, metavar='N',
                        help='trials at once (default: every CPU of the local machine, or of '
                             'the cluster with --address)')
    parser.add_argument('--address', metavar='ADDR',
                        help="join this Ray cluster (e.g. 'auto' or head-ip:6379) instead of "
                             'starting one')
    args = parser.parse_args(argv)
    if args.workers is not None and args.workers < 1:
        _refuse(f'--workers must be >= 1, got {args.workers}')
    try:
        trials = plan_trials(load_sweep(args.sweep))
        finished = finished_keys(args.out)
        with args.out.open('a'):  # writable, before Ray starts
            pass
    except (SweepError, OSError) as error:
        _refuse(str(error))
    todo = [spec for spec in trials if spec.key() not in finished]
    print(f'campaign: {len(trials)} trials, {len(trials) - len(todo)} already in {args.out}, '
          f'{len(todo)} to run', file=sys.stderr, flush=True)
    if not todo:
        return
    try:
        with ray_session(args.workers, args.address) as at_once, \
                contextlib.closing(ray_results(todo, at_once)) as results:
            failed = record(results, args.out, len(todo))
    except KeyboardInterrupt:
        print(f'campaign: interrupted; the finished trials are in {args.out}: run the same '
              'command to go on', file=sys.stderr)
        sys.exit(130)
    if failed:
        print(f'campaign: {failed} trial(s) failed and were not written: run the same '
              'command to retry them', file=sys.stderr)
        sys.exit(1)


if __name__ == '__main__':
    # Ray ships functions of __main__ by value: hand it the importable module's.
    from swivel_car_studies import campaign
    campaign.main()
