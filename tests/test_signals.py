"""
Ctrl-C (SIGINT) and SIGTERM end every node of a busy stack with exit code 0 and no traceback.

Before (issue 12), the controller ended with exit 1 and an RCLError traceback, "publisher's
context is invalid", when the signal landed while it answered a joint_states; the sim with
"failed to initialize wait set"; later (SIGTERM) the controller logged its failed publish as
FATAL with a stack and still ended with exit 0.
"""

import signal
import time

import pytest
from swivel_car_testing import next_domain_id, NodeProcess

SIM_TIME = {'use_sim_time': True}
PLANNER = ('swivel_car_planner', 'planner_node', SIM_TIME)
# Started once the planner is ready (it starts slowest): an unpaced stack would run for
# nothing meanwhile.
NODES = [('swivel_car_control', 'controller_node', SIM_TIME),
         ('swivel_car_control', 'odometry_node', SIM_TIME),
         # Lockstep as fast as the controller answers: every node is in a callback most of
         # the time, where the signal must land to show the fault.
         ('swivel_car_sim', 'sim_node', {'lockstep': True, 'lockstep_timeout': 1.0})]


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM],
                         ids=lambda s: signal.Signals(s).name)
def test_a_signal_ends_every_busy_node_with_exit_0_and_no_traceback(signum):
    domain_id = next_domain_id()
    processes = [NodeProcess(*PLANNER[:2], domain_id, PLANNER[2])]
    try:
        processes[0].wait_for_output('planner ready', 60.0)
        processes += [NodeProcess(package, executable, domain_id, parameters)
                      for package, executable, parameters in NODES]
        # Up and answering: the controller has logged its start and the sim runs.
        processes[1].wait_for_output('controller up', 60.0)
        time.sleep(0.5)  # some 500 lockstep periods: every node busy
        for process in processes:
            process.process.send_signal(signum)
            code = process.process.wait(15.0)
            output = process.output()
            assert code == 0, f'{process.name}: {output}'
            # The EventsExecutor logs a callback's failure as FATAL, its stack as a warning.
            for sign in ('Traceback', 'FATAL', 'Error occurred'):
                assert sign not in output, f'{process.name}: {output}'
    finally:
        for process in processes:
            process.stop()
