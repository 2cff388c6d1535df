"""
Every node console script the packages declare is installed where `ros2 run` looks.

That is install/<pkg>/lib/<pkg>/; each starts as a node and exits cleanly on SIGINT.
"""

from __future__ import annotations

import ast
import itertools
import os

import pytest
from rclpy.experimental import EventsExecutor
from rclpy.node import Node
from swivel_car_testing import executable_path, NodeProcess, REPO_ROOT, spin_until

_STARTS = itertools.count()
PYTHON_PACKAGES = sorted(path.parent.name for path in REPO_ROOT.glob('swivel_car_*/setup.py'))


def console_scripts(package: str) -> list[str]:
    """Return the console script names in ``package``'s setup.py."""
    tree = ast.parse((REPO_ROOT / package / 'setup.py').read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for key, value in zip(node.keys, node.values):
                if isinstance(key, ast.Constant) and key.value == 'console_scripts':
                    return [ast.literal_eval(item).split('=')[0].strip() for item in value.elts]
    return []


# Nodes; the other console scripts (the campaign command) have tests of their own.
EXECUTABLES = [(package, script) for package in PYTHON_PACKAGES
               for script in console_scripts(package) if script.endswith('_node')]


def test_every_node_package_declares_executables():
    assert {package for package, _ in EXECUTABLES} >= {
        'swivel_car_sim', 'swivel_car_control', 'swivel_car_planner'}


@pytest.mark.parametrize('package, executable', EXECUTABLES, ids=lambda v: str(v))
def test_executable_installed_and_starts(ros_domain, package, executable):
    domain_id, context = ros_domain
    path = executable_path(package, executable)
    assert path.stat().st_mode & 0o111, f'{path} is not executable'
    # The node is named after its executable (sim_node: 'sim'), in a namespace of this test's
    # own: the domain ids come round again, and a node of that name killed by an earlier test
    # stays in the graph for seconds; seen there, it would end the wait while this one still
    # imports, and SIGINT would then end the import with a traceback.
    namespace = f'/executable_test_{os.getpid()}_{next(_STARTS)}'
    process = NodeProcess(package, executable, domain_id,
                          extra_args=('--ros-args', '-r', f'__ns:={namespace}'))
    probe = Node('executable_probe', context=context)
    executor = EventsExecutor(context=context)
    executor.add_node(probe)
    try:
        node = (executable.removesuffix('_node'), namespace)
        spin_until(executor, lambda: not process.running()
                   or node in probe.get_node_names_and_namespaces(),
                   30.0, f'{executable} to join the ROS graph as {namespace}/{node[0]}')
        assert process.running(), process.output()
        assert process.stop() == 0, process.output()
    finally:
        if process.running():
            process.kill()
        executor.shutdown()
        probe.destroy_node()
