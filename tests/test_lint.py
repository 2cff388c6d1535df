"""
The code style of every Python file: ament_flake8 and ament_pep257.

Both with their default configuration, as every ROS 2 ament_python package's test_flake8.py
and test_pep257.py run them; here over the whole repository at once (the packages, the
scripts and the tests), since scripts/ and tests/ belong to no package. Each runs in a process
of its own: flake8 forks its workers, and a fork of a test process that has run rclpy's threads
can hang.
"""

from pathlib import Path
import subprocess
import sys

import pytest

REPO = Path(__file__).resolve().parents[1]
PATHS = [str(path) for path in sorted(REPO.glob('swivel_car_*/')) + [
    REPO / 'scripts', REPO / 'tests', REPO / 'conftest.py']]


@pytest.mark.parametrize('linter', ['ament_flake8', 'ament_pep257'])
def test_lint(linter):
    done = subprocess.run([sys.executable, '-m', f'{linter}.main', *PATHS],
                          capture_output=True, text=True, timeout=240)
    assert done.returncode == 0, done.stdout[-20000:] + done.stderr[-5000:]
