"""
The code style of every Python file: ament_flake8 and ament_pep257.

Both with their default configuration, as every ROS 2 ament_python package's test_flake8.py
and test_pep257.py run them; here over the whole repository at once (the packages, the
scripts and the tests), since scripts/ and tests/ belong to no package.
"""

from pathlib import Path

from ament_flake8.main import main_with_errors as flake8_main
from ament_pep257.main import main as pep257_main

REPO = Path(__file__).resolve().parents[1]
PATHS = [str(path) for path in sorted(REPO.glob('swivel_car_*/')) + [
    REPO / 'scripts', REPO / 'tests', REPO / 'conftest.py']]


def test_flake8():
    status, errors = flake8_main(argv=PATHS)
    assert status == 0, f'{len(errors)} flake8 findings:\n' + '\n'.join(errors)


def test_pep257():
    assert pep257_main(argv=PATHS) == 0, 'pep257 findings: see the captured output'
