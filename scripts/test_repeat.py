#!/usr/bin/env python3
"""
Run the whole test suite several times and count which tests failed how often.

A flake hunt: ``make test-repeat RUNS=5 HOG=1`` (or ``scripts/in_ws python
scripts/test_repeat.py --runs 5 --hog``). Each run is ``make test``'s pytest command; with
``--hog`` one process keeps one core busy throughout, as another job on the machine would.
Prints a line per run, each test that failed with how often, and a summary line; the exit code
is 0 only if every run was green. The JUnit reports of red runs (every failure in full, with
the nodes' logs the system tests attach) are kept in a directory it names.
"""

import argparse
import collections
from pathlib import Path
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ElementTree

ROOT = Path(__file__).resolve().parent.parent
HOG = 'while True: pass'  # one core busy, nothing else


def failed_tests(report: Path) -> list[str]:
    """Return the failed or erroring tests of a JUnit XML report, as module.Class::name."""
    if not report.exists():
        return ['(no report: pytest did not finish)']
    failed = []
    for case in ElementTree.parse(report).getroot().iter('testcase'):
        problem = case.find('failure')
        problem = case.find('error') if problem is None else problem
        if problem is not None:
            where = case.get('classname', '')
            name = f'{where}::{case.get("name")}' if where else case.get('name')
            message = (problem.get('message') or '').splitlines()
            print(f'  {name}: {message[0][:200] if message else "(no message)"}', flush=True)
            failed.append(name)
    return failed


def run_once(workers: str, extra: list[str], report: Path) -> tuple[int, float]:
    """Run the suite once as ``make test`` does; return its exit code and wall time [s]."""
    command = [sys.executable, '-m', 'pytest', '-q', '-p', 'no:cacheprovider',
               '-n', workers, '--dist', 'loadfile', '--no-loadscope-reorder',
               f'--junitxml={report}', *extra]
    start = time.monotonic()
    code = subprocess.run(command, cwd=ROOT, stdout=subprocess.DEVNULL,
                          stderr=subprocess.DEVNULL).returncode
    return code, time.monotonic() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument('--runs', type=int, default=5, help='how many runs (default 5)')
    parser.add_argument('--hog', action='store_true', help='keep one core busy meanwhile')
    parser.add_argument('--workers', default='auto',
                        help="pytest-xdist workers, as make test (default: auto, conftest.py's)")
    parser.add_argument('pytest_args', nargs='*', help='more pytest arguments')
    args = parser.parse_args()
    if args.runs < 1:
        parser.error('--runs must be at least 1')
    hog = subprocess.Popen([sys.executable, '-c', HOG]) if args.hog else None
    failures: collections.Counter[str] = collections.Counter()
    green = 0
    reports = Path(tempfile.mkdtemp(prefix='swivel-car-test-repeat-'))
    try:
        for run in range(1, args.runs + 1):
            report = reports / f'run{run}.xml'
            code, seconds = run_once(args.workers, args.pytest_args, report)
            failed = failed_tests(report) if code else []
            if code and not failed:
                failed = [f'(pytest exit code {code}, no failed test reported)']
            failures.update(failed)
            green += not failed
            if not failed:
                report.unlink(missing_ok=True)
            print(f'run {run}/{args.runs}: {"green" if not failed else "RED"} in '
                  f'{seconds:.0f} s' + ''.join(f'\n  failed: {t}' for t in failed),
                  flush=True)
    finally:
        if hog is not None:
            hog.kill()
            hog.wait()
    for test, count in failures.most_common():
        print(f'{count} of {args.runs} runs failed: {test}')
    if any(reports.iterdir()):
        print(f'JUnit reports of the red runs: {reports}')
    else:
        reports.rmdir()
    load = 'with one core busy' if args.hog else 'without load'
    print(f'{green} of {args.runs} runs green ({load}); {len(failures)} tests failed at least '
          'once')
    return 0 if green == args.runs else 1


if __name__ == '__main__':
    sys.exit(main())
