"""
The launch files, checked without running them.

They are for users with a full Jazzy install (launch_ros is not installable here), so they
cannot run in this suite. Parse each one instead and check that every executable and
parameter file it names is installed where launch_ros will look.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from swivel_car_testing import executable_path, INSTALL_DIR, REPO_ROOT

LAUNCH_FILES = sorted(REPO_ROOT.glob('swivel_car_*/launch/*.launch.py'))


def _keyword_constants(call: ast.Call) -> dict[str, str]:
    return {kw.arg: kw.value.value for kw in call.keywords
            if isinstance(kw.value, ast.Constant) and isinstance(kw.value.value, str)}


def _called_name(call: ast.Call) -> str:
    return call.func.attr if isinstance(call.func, ast.Attribute) else getattr(
        call.func, 'id', '')


def test_every_node_package_has_a_launch_file():
    assert {path.parts[-3] for path in LAUNCH_FILES} >= {
        'swivel_car_sim', 'swivel_car_control', 'swivel_car_planner'}


@pytest.mark.parametrize('launch_file', LAUNCH_FILES, ids=lambda p: f'{p.parts[-3]}/{p.name}')
def test_launch_file_names_installed_things(launch_file: Path):
    package = launch_file.parts[-3]
    tree = ast.parse(launch_file.read_text(), filename=str(launch_file))
    functions = {node.name for node in tree.body if isinstance(node, ast.FunctionDef)}
    assert 'generate_launch_description' in functions
    assert (INSTALL_DIR / package / 'share' / package / 'launch' / launch_file.name).exists()

    calls = [node for node in ast.walk(tree) if isinstance(node, ast.Call)]
    nodes = [_keyword_constants(call) for call in calls if _called_name(call) == 'Node']
    assert nodes or any(_called_name(call) == 'IncludeLaunchDescription' for call in calls)
    for node in nodes:
        assert executable_path(node.get('package', package), node['executable'])

    yaml_names = {node.value for node in ast.walk(tree) if isinstance(node, ast.Constant)
                  and isinstance(node.value, str) and node.value.endswith('.yaml')}
    for name in yaml_names:
        installed = list((INSTALL_DIR / package / 'share' / package).rglob(Path(name).name))
        assert installed, f'{launch_file.name} names {name}, not installed in share/{package}'

    included = {node.value for node in ast.walk(tree) if isinstance(node, ast.Constant)
                and isinstance(node.value, str) and node.value.endswith('.launch.py')}
    for name in included:
        assert list(INSTALL_DIR.glob(f'*/share/*/launch/{name}')), f'{name} is not installed'


def _respawned(launch_file: Path) -> dict[str, bool]:
    """Map each executable to whether its Node action has respawn=True."""
    tree = ast.parse(launch_file.read_text(), filename=str(launch_file))
    found = {}
    for call in ast.walk(tree):
        if isinstance(call, ast.Call) and _called_name(call) == 'Node':
            keywords = {kw.arg: kw.value for kw in call.keywords}
            respawn = keywords.get('respawn')
            found[keywords['executable'].value] = isinstance(respawn, ast.Constant) \
                and respawn.value is True
    return found


def test_a_dead_node_is_started_again_where_that_is_safe():
    respawned = {}
    for launch_file in LAUNCH_FILES:
        respawned.update(_respawned(launch_file))
    assert respawned['controller_node'] and respawned['odometry_node']
    assert respawned['planner_node']
    assert not respawned['sim_node']  # a new sim is a new world
