"""
The command-line scripts under scripts/ import and parse their arguments.

Nothing else imports them: a helper moved out of one script would break another that imports
it only when that script runs (`make soak`, say).
"""

import importlib
from pathlib import Path
import time

import pytest
from swivel_car_testing import next_domain_id, start_node

SCRIPTS = ['chain_benchmark', 'demo', 'node_docs', 'soak']


@pytest.mark.parametrize('name', SCRIPTS)
def test_a_script_imports_and_answers_help(name, capsys):
    script = importlib.import_module(name)
    with pytest.raises(SystemExit) as exit_info:
        script.main(['--help'])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.startswith('usage:')


def test_a_node_process_keeps_its_output_and_deletes_its_log_once_stopped():
    # Every test run starts some 60 node processes: their logs must not pile up in /tmp.
    process = start_node('swivel_car_sim', 'sim_node', next_domain_id(), {})
    log = Path(process.log.name)
    deadline = time.monotonic() + 60.0
    while 'swivel car, time_step' not in process.output():
        assert process.running() and time.monotonic() < deadline, process.output()
        time.sleep(0.1)
    assert log.is_file()
    assert process.stop() == 0
    assert not log.exists()
    assert 'swivel car, time_step' in process.output()
