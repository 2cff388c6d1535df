#!/usr/bin/env python3
"""
Write the byte code of every installed module this repository imports, once.

``scripts/in_ws python scripts/warm_bytecode.py``; ``make build`` runs it beside colcon.

uv installs without byte code, and Python writes a module's ``.pyc`` the first time a process
imports it (to the venv's pycache, ``scripts/ws_env.sh``). ``make test`` starts its test
workers, and they their nodes, at the same moment: each compiled numpy, scipy, rclpy and the
rest again, side by side. Compiling the whole venv ahead costs more than that, most of it on
modules nothing imports; this imports only the modules an ``import`` statement in the
repository names, from outside the repository (the venv's, the system's). A module that does
not import here (one of the workspace being built, or an optional one) is skipped: its byte
code is then written when it is first imported, as without this.
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
from pathlib import Path
import sys

REPO = Path(__file__).resolve().parents[1]
SKIPPED_DIRECTORIES = {'.venv', 'ros2_ws', 'node_modules', '.git'}


def imported_names(root: Path) -> set[str]:
    """Return the absolute module names of the import statements in ``root``'s Python files."""
    names: set[str] = set()
    for path in root.rglob('*.py'):
        if SKIPPED_DIRECTORIES.intersection(path.relative_to(root).parts):
            continue
        for node in ast.walk(ast.parse(path.read_bytes(), str(path))):
            if isinstance(node, ast.Import):
                names.update(alias.name for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                names.add(node.module)
    return names


def installed(name: str) -> bool:
    """Whether the top-level package of ``name`` is installed outside the repository's sources."""
    top = name.partition('.')[0]
    if top in sys.stdlib_module_names:
        return False
    try:
        spec = importlib.util.find_spec(top)
    except (ImportError, ValueError):
        return False
    if spec is None:
        return False
    location = spec.origin if spec.has_location else next(
        iter(spec.submodule_search_locations or ()), None)
    if location is None:
        return False
    path = Path(location).resolve()
    return REPO not in path.parents or REPO / '.venv' in path.parents


def main() -> None:
    for name in sorted(filter(installed, imported_names(REPO))):
        try:
            importlib.import_module(name)
        except Exception:  # noqa: B902 any failure only leaves its byte code for later
            continue


if __name__ == '__main__':
    main()
