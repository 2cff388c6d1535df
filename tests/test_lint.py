"""
The code style of every Python file: ament_flake8, ament_pep257 and flake8's mccabe check.

Both with their default configuration, as every ROS 2 ament_python package's test_flake8.py
and test_pep257.py run them; here over the whole repository at once (the packages, the
scripts and the tests), since scripts/ and tests/ belong to no package. Each runs in a process
of its own: flake8 forks its workers, and a fork of a test process that has run rclpy's threads
can hang.
"""

import ast
from pathlib import Path
import subprocess
import sys

import mccabe
import pytest

REPO = Path(__file__).resolve().parents[1]
PATHS = [str(path) for path in sorted(REPO.glob('swivel_car_*/')) + [
    REPO / 'scripts', REPO / 'tests', REPO / 'conftest.py']]
# flake8's --max-complexity (C901: a function's McCabe complexity above it). Just above the
# worst function after the climb became one class per step (19, a flat run of parameter
# checks); the if-chain over the climb's steps it replaced was 33.
MAX_COMPLEXITY = 20


@pytest.mark.parametrize('linter', ['ament_flake8', 'ament_pep257'])
def test_lint(linter):
    done = subprocess.run([sys.executable, '-m', f'{linter}.main', *PATHS],
                          capture_output=True, text=True, timeout=240)
    assert done.returncode == 0, done.stdout[-20000:] + done.stderr[-5000:]


def test_no_function_is_more_complex_than_max_complexity():
    """flake8's C901, with the mccabe module flake8 runs, in-process (no second flake8 run)."""
    too_complex = []
    for root in map(Path, PATHS):
        for path in sorted(root.rglob('*.py')) if root.is_dir() else [root]:
            tree = compile(path.read_text(), str(path), 'exec', ast.PyCF_ONLY_AST)
            visitor = mccabe.PathGraphingAstVisitor()
            visitor.preorder(tree, visitor)
            too_complex += [f'{path.relative_to(REPO)}:{graph.lineno}: C901 {graph.entity} is '
                            f'too complex ({graph.complexity()})'
                            for graph in visitor.graphs.values()
                            if graph.complexity() > MAX_COMPLEXITY]
    assert not too_complex, '\n'.join(too_complex)
