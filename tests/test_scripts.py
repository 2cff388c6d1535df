"""
The command-line scripts under scripts/ import and parse their arguments.

`make soak` once failed at start: scripts/soak.py imported a helper that had moved out of
scripts/demo.py, and no test imported it.
"""

import importlib

import pytest

SCRIPTS = ['chain_benchmark', 'demo', 'node_docs', 'soak']


@pytest.mark.parametrize('name', SCRIPTS)
def test_a_script_imports_and_answers_help(name, capsys):
    script = importlib.import_module(name)
    with pytest.raises(SystemExit) as exit_info:
        script.main(['--help'])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.startswith('usage:')
