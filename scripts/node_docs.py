#!/usr/bin/env python3
"""
The README's node tables, generated from the nodes themselves.

Each node is constructed in-process with its defaults and asked, as `ros2 node info` and
`ros2 param describe` would, for its topics, services, actions and parameters. So the tables
cannot drift from the code.

    scripts/in_ws python scripts/node_docs.py --write README.md   # regenerate
    scripts/in_ws python scripts/node_docs.py --check README.md   # exit 1 if stale (a test)
"""

from __future__ import annotations

import argparse
from pathlib import Path
import sys
import time

import rclpy
from rclpy.action import get_action_server_names_and_types_by_node
from rclpy.node import Node
from swivel_car_control.controller_node import ControllerNode
from swivel_car_control.odometry_node import OdometryNode
from swivel_car_perception.step_detector_node import StepDetectorNode
from swivel_car_planner.planner_node import PlannerNode
from swivel_car_sim.sim_node import SimNode

BEGIN, END = '<!-- node tables: begin (scripts/node_docs.py) -->', '<!-- node tables: end -->'
NODES = (('swivel_car_sim', 'sim_node', SimNode), ('swivel_car_control', 'controller_node',
         ControllerNode), ('swivel_car_control', 'odometry_node', OdometryNode),
         ('swivel_car_planner', 'planner_node', PlannerNode),
         ('swivel_car_perception', 'step_detector_node', StepDetectorNode))
# Every node has these; `ros2 param` documents them.
STANDARD_SERVICES = {'describe_parameters', 'get_parameter_types', 'get_parameters',
                     'get_type_description', 'list_parameters', 'set_parameters',
                     'set_parameters_atomically'}
STANDARD_TOPICS = {'/parameter_events', '/rosout'}
STANDARD_PARAMETERS = {'use_sim_time', 'start_type_description_service'}


def _names(pairs, skip) -> list[tuple[str, str]]:
    return sorted((name, ', '.join(types)) for name, types in pairs
                  if not skip(name) and '/_action/' not in name)


def node_table(package: str, executable: str, node: Node) -> str:
    name, namespace = node.get_name(), node.get_namespace()
    deadline = time.monotonic() + 10.0
    while time.monotonic() < deadline:  # the graph learns of the node's own entities
        services = node.get_service_names_and_types_by_node(name, namespace)
        if services:
            break
        time.sleep(0.05)
    rows = []
    for kind, pairs in (
            ('publishes', node.get_publisher_names_and_types_by_node(name, namespace)),
            ('subscribes', node.get_subscriber_names_and_types_by_node(name, namespace)),
            ('service', node.get_service_names_and_types_by_node(name, namespace)),
            ('action', get_action_server_names_and_types_by_node(node, name, namespace))):
        for topic, types in _names(pairs, lambda n: n in STANDARD_TOPICS or n.rsplit(
                '/', 1)[-1] in STANDARD_SERVICES):
            rows.append(f'| {kind} | `{topic}` | {types} |')
    parameters = []
    for parameter_name in sorted(node._parameters):
        if parameter_name in STANDARD_PARAMETERS:
            continue
        value = node.get_parameter(parameter_name).value
        description = node.describe_parameter(parameter_name).description.replace('|', '\\|')
        parameters.append(f'| `{parameter_name}` | {value!r} | {description} |')
    return '\n'.join([
        f'### `{name}`: `ros2 run {package} {executable}`', '',
        '| kind | name | type |', '|---|---|---|', *rows, '',
        '| parameter | default | description |', '|---|---|---|', *parameters, ''])


def generate() -> str:
    rclpy.init()
    try:
        tables = []
        for package, executable, node_class in NODES:
            node = node_class()
            try:
                tables.append(node_table(package, executable, node))
            finally:
                node.destroy_node()
        return '\n'.join(tables)
    finally:
        rclpy.try_shutdown()


def splice(text: str, tables: str) -> str:
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    return f'{head}{BEGIN}\n{tables}{END}{tail}'


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument('--write', type=Path, help='rewrite the tables in this file')
    group.add_argument('--check', type=Path, help='exit 1 if the tables in this file are stale')
    args = parser.parse_args(argv)
    path = args.write or args.check
    text = path.read_text()
    updated = splice(text, generate())
    if args.write:
        path.write_text(updated)
        return 0
    if updated != text:
        print(f'{path}: node tables are stale; run scripts/node_docs.py --write {path}',
              file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
