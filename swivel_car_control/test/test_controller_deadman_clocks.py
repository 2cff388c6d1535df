"""
The controller core's deadmans count in the time of its steps, whatever clock stamped a command.

Before (issue 12), after a runtime use_sim_time flip, a /clock of 2^31-1 s or a restarted sim,
the car went on driving with no one commanding it.
"""

import math

from hypothesis import given, settings, strategies as st
import pytest

from swivel_car_control.core.controller import (
    ControllerConfig, SOURCE_HOLD, SOURCE_SWIVEL_COMMAND, SwivelController)
from swivel_car_model.description import CarDescription

P = CarDescription().model_params()
DT = 0.01  # [s]
TIMEOUT = 0.5  # [s]


def make():
    return SwivelController(P, ControllerConfig(cmd_vel_timeout=TIMEOUT,
                                                swivel_command_timeout=TIMEOUT))


def run(controller, t0, seconds):
    out = None
    for k in range(int(round(seconds / DT))):
        out = controller.step(t0 + k * DT, out.set_point if out else 0.0, 0.0)
    return out


# Stamps from other clocks: wall time against sim time, a /clock of 2^31-1 s.
FOREIGN_STAMPS = [1.79e9, 2.0**31 - 1, 10.5]


@pytest.mark.parametrize('stamp', FOREIGN_STAMPS)
def test_a_cmd_vel_stamped_ahead_of_the_steps_times_out_after_the_timeout(stamp):
    controller = make()
    run(controller, 5.0, 0.1)
    controller.set_cmd_vel(0.3, 0.0, stamp)
    out = run(controller, 5.1, TIMEOUT)
    assert not out.cmd_vel_timed_out and out.drive_speed > 0.0
    out = run(controller, 5.1 + TIMEOUT, 2 * DT)
    assert out.cmd_vel_timed_out
    assert run(controller, 5.2 + TIMEOUT, 1.0).drive_speed == 0.0


@pytest.mark.parametrize('stamp', FOREIGN_STAMPS)
def test_a_swivel_command_stamped_ahead_of_the_steps_is_released_after_the_timeout(stamp):
    controller = make()
    run(controller, 5.0, 0.1)
    controller.set_swivel_command(0.0, 0.0, 3.0, True, stamp)
    out = run(controller, 5.1, TIMEOUT)
    assert out.source == SOURCE_SWIVEL_COMMAND and out.drive_speed > 0.0
    run(controller, 5.1 + TIMEOUT, 2 * DT)
    assert controller.swivel_command is None
    out = run(controller, 5.2 + TIMEOUT, 1.0)
    assert out.source == SOURCE_HOLD and out.drive_speed == 0.0


def test_a_restarted_sim_drops_the_commands_of_the_old_run():
    """The planner and the sim were killed mid-climb; the new sim's time starts at 0."""
    controller = make()
    controller.set_swivel_command(0.0, 0.0, 3.0, True, 50.0)
    controller.set_cmd_vel(0.3, 0.0, 50.0)
    assert run(controller, 50.0, 0.2).drive_speed > 0.0
    out = controller.step(0.0, 0.0, 0.0)
    assert controller.swivel_command is None
    assert out.source == SOURCE_HOLD and out.drive_speed == 0.0
    assert run(controller, DT, 1.0).drive_speed == 0.0


@settings(max_examples=200)
@given(stamp=st.floats(-1e12, 1e12), start=st.floats(0.0, 1e6))
def test_no_stamp_keeps_a_command_alive_longer_than_its_timeout_of_steps(stamp, start):
    """At most the timeout after the first step that sees the command, whatever its stamp."""
    controller = make()
    controller.step(start, 0.0, 0.0)
    controller.set_cmd_vel(0.3, 0.0, stamp)
    controller.set_swivel_command(0.0, 0.0, 3.0, True, stamp)
    for k in range(1, int(round(TIMEOUT / DT)) + 3):
        out = controller.step(start + k * DT, 0.0, 0.0)
    assert controller.swivel_command is None
    assert out.cmd_vel_timed_out
    assert not math.isnan(out.drive_speed)
