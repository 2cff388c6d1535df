"""Unit tests of the controller core: arbitration, deadman, limits, guards."""

import dataclasses
import math

from hypothesis import given, settings, strategies as st
import pytest

from swivel_car_control.core.controller import (
    ControllerConfig, SOURCE_CMD_VEL, SOURCE_HOLD, SOURCE_SWIVEL_COMMAND, SwivelController)
from swivel_car_model.params import SwivelCarParams

P = SwivelCarParams()
DT = 0.01  # [s]


def make(p=P, **overrides):
    return SwivelController(p, ControllerConfig(**overrides))


def run(controller, t0, seconds, measured=None):
    """
    Step ``controller`` for ``seconds`` from ``t0`` and return its last output.

    The swivel sits at ``measured`` or, if None, follows the set point perfectly.
    """
    out = None
    for k in range(int(round(seconds / DT))):
        angle = measured if measured is not None else (out.set_point if out else 0.0)
        out = controller.step(t0 + k * DT, angle, 0.0)
    return out


def test_config_validation():
    for bad in ({'max_torque': 0.0}, {'cmd_vel_timeout': -1.0}, {'max_swivel_rate': math.nan},
                {'swivel_command_timeout': -0.5}, {'swivel_command_timeout': math.inf},
                {'slowdown_start': 0.5, 'slowdown_stop': 0.2}):
        with pytest.raises(ValueError):
            ControllerConfig(**bad)


def test_starts_holding_the_measured_swivel():
    controller = make()
    out = controller.step(0.0, 0.3, 0.0)
    assert out.source == SOURCE_HOLD
    assert out.set_point == pytest.approx(0.3)
    assert out.drive_speed == 0.0


def test_cmd_vel_steers_and_drives_within_limits():
    controller = make()
    controller.set_cmd_vel(0.4, -0.4, 0.0)
    out = controller.step(0.0, 0.0, 0.0)
    for k in range(1, 200):
        previous = out
        controller.set_cmd_vel(0.4, -0.4, k * DT)
        out = controller.step(k * DT, out.set_point, 0.0)
        assert abs(out.drive_speed - previous.drive_speed) * P.r <= 1.0 * DT + 1e-12
        assert abs(out.set_point - previous.set_point) <= 1.5 * DT + 1e-12
    assert out.source == SOURCE_CMD_VEL
    assert out.target > 0.0  # right turn: positive swivel for phi > 0
    assert out.v_out == pytest.approx(0.4)
    assert out.omega_out == pytest.approx(-0.4)


def test_drive_waits_for_the_swivel():
    controller = make()
    controller.set_cmd_vel(0.0, 1.0, 0.0)
    for k in range(100):
        out = controller.step(k * DT, 0.0, 0.0)  # the swivel is stuck at zero
    assert abs(out.target) > 1.0
    assert out.drive_speed == 0.0


def test_deadman_stops_the_drive_and_holds_the_swivel():
    controller = make(cmd_vel_timeout=0.5)
    controller.set_cmd_vel(0.3, 0.5, 0.0)
    out = run(controller, 0.0, 0.5)
    held = out.target
    assert out.drive_speed > 0.0 and not out.cmd_vel_timed_out
    out = run(controller, 0.5, 2.0)
    assert out.cmd_vel_timed_out
    assert out.drive_speed == 0.0
    assert out.source == SOURCE_HOLD
    assert out.target == held


def test_zero_timeout_disables_the_deadman():
    controller = make(cmd_vel_timeout=0.0)
    controller.set_cmd_vel(0.3, 0.0, 0.0)
    out = run(controller, 0.0, 20.0)
    assert out.drive_speed == pytest.approx(0.3 / P.r)


@settings(max_examples=20)
@given(bad=st.sampled_from([math.nan, math.inf, -math.inf]), slot=st.integers(0, 2))
def test_non_finite_cmd_vel_keeps_the_last_safe_command(bad, slot):
    controller = make(cmd_vel_timeout=0.0)
    controller.set_cmd_vel(0.2, 0.0, 0.0)
    before = run(controller, 0.0, 1.0)
    args = [0.2, 0.0, 1.0]
    args[slot] = bad
    with pytest.raises(ValueError, match='rejected'):
        controller.set_cmd_vel(*args)
    after = run(controller, 1.0, 0.5)
    assert after.drive_speed == before.drive_speed
    assert after.target == before.target


def test_swivel_command_takes_over_and_releases():
    controller = make(cmd_vel_timeout=0.0, swivel_command_timeout=0.0)
    controller.set_cmd_vel(0.2, 0.0, 0.0)
    run(controller, 0.0, 0.5)
    controller.set_swivel_command(0.6, 0.2, 1.0, True, 0.5)
    out = run(controller, 0.5, 1.0, measured=0.6)
    assert out.source == SOURCE_SWIVEL_COMMAND
    assert out.target == 0.6
    assert out.set_point == pytest.approx(0.2, abs=0.011)  # its own rate limit, 0.2 rad/s
    assert out.drive_speed == pytest.approx(1.0)
    controller.set_swivel_command(0.0, 0.0, 0.0, False, 1.5)
    out = run(controller, 1.5, 1.0)
    assert out.source == SOURCE_CMD_VEL
    assert out.target == 0.0


def test_free_swivel_command_gives_no_torque_and_holds_at_the_tip_safe_limit():
    controller = make(cmd_vel_timeout=0.0, swivel_command_timeout=0.0)
    run(controller, 0.0, 0.2, measured=0.0)
    controller.set_swivel_command(0.0, 0.0, 3.0, True, 0.2, free=True)
    for k, angle in enumerate((0.1, 0.3, -0.4, 0.2)):  # the load turns the swivel
        out = controller.step(0.2 + (k + 1) * DT, angle, 5.0)
        assert out.swivel_torque == 0.0
        assert out.target == angle and out.set_point == angle
        assert out.source == SOURCE_SWIVEL_COMMAND
    assert out.drive_speed > 0.0
    beyond = controller.swivel_limit + 0.05
    out = controller.step(0.3, beyond, 0.0)
    assert out.target == controller.swivel_limit and out.swivel_torque < 0.0
    # Held again from where it is: no jump of the set point.
    controller.set_swivel_command(0.5, 0.0, 0.0, True, 0.3)
    out = controller.step(0.31, 0.2, 0.0)
    # One period's slew at max_swivel_rate (1.5 rad/s x 10 ms = 0.015 rad) towards the new
    # target; a jump would move it the whole 0.9 rad to 0.5 rad.
    assert out.set_point == pytest.approx(controller.swivel_limit, abs=0.02)


def test_stale_swivel_command_is_released_holding_the_swivel():
    """
    Check a stale swivel command is released and the swivel held where it left it.

    The planner died: its last command (driving, swivel at 0.6) expires, the drive stops, the
    swivel holds where the command left it, and cmd_vel steers again.
    """
    controller = make(cmd_vel_timeout=0.0, swivel_command_timeout=0.5)
    controller.set_swivel_command(0.6, 0.0, 2.0, True, 0.0)
    out = run(controller, 0.0, 0.5)
    assert out.source == SOURCE_SWIVEL_COMMAND and not out.swivel_command_timed_out
    assert out.drive_speed > 0.0
    out = controller.step(0.51, out.set_point, 0.0)
    assert out.swivel_command_timed_out and controller.swivel_command is None
    out = run(controller, 0.52, 1.5)
    assert out.source == SOURCE_HOLD and not out.swivel_command_timed_out
    assert out.target == 0.6 and out.drive_speed == 0.0
    controller.set_cmd_vel(0.2, 0.0, 2.02)
    assert run(controller, 2.02, 0.5).source == SOURCE_CMD_VEL


def test_swivel_command_refusals_change_nothing():
    controller = make(dataclasses.replace(P, swivel_limit=1.2))
    controller.set_swivel_command(0.5, 0.0, 0.0, True, 0.0)
    for args, match in (((1.3, 0.0, 0.0), 'outside'), ((math.nan, 0.0, 0.0), 'angle'),
                        ((0.1, -1.0, 0.0), 'max_rate'), ((0.1, 0.0, math.inf), 'drive_speed')):
        with pytest.raises(ValueError, match=match):
            controller.set_swivel_command(*args, True, 0.0)
    with pytest.raises(ValueError, match='stamp'):
        controller.set_swivel_command(0.1, 0.0, 0.0, True, math.nan)
    assert controller.swivel_command.angle == 0.5


def test_swivel_command_breaking_the_tip_over_rule_is_refused():
    margin = (math.pi - P.phi) / 2 - 0.1  # allows only a lift angle of 0.1 rad
    controller = make(tip_over_margin=margin)
    assert controller.swivel_limit < 1.4
    with pytest.raises(ValueError, match='tip-over'):
        controller.set_swivel_command(1.0, 0.0, 0.0, True, 0.0)
    assert controller.swivel_command is None


def test_time_going_back_restarts():
    controller = make()
    controller.set_cmd_vel(0.3, 0.0, 5.0)
    run(controller, 5.0, 1.0)
    out = controller.step(0.0, 0.2, 0.0)
    assert out.pid.i_term == 0.0
    assert out.set_point == pytest.approx(0.2)


def test_a_world_reset_drops_the_commands_and_holds_the_swivel_measured_after_it():
    """
    Check a world reset drops the commands and holds the swivel measured after it.

    The sim's ~/reset put the car back at rest with the swivel at 0 while the controller held
    0.6 rad: it re-steered to 0.6 (found by the soak).
    """
    controller = make(cmd_vel_timeout=0.0, swivel_command_timeout=0.0)
    controller.set_cmd_vel(0.2, 0.4, 0.0)
    run(controller, 0.0, 1.0)
    controller.set_swivel_command(0.6, 0.0, 2.0, True, 1.0)
    run(controller, 1.0, 1.0)
    controller.reset(2.0)
    assert controller.swivel_command is None
    # A state from before the reset, still on its way: no restart yet (its swivel is 0.6).
    before = controller.step(1.995, 0.6, 0.0)
    assert before.source == SOURCE_HOLD and before.target == 0.6
    after = controller.step(2.0, 0.0, 0.0)
    assert after.source == SOURCE_HOLD and after.target == 0.0 and after.set_point == 0.0
    assert after.swivel_torque == 0.0 and after.drive_speed == 0.0
    later = run(controller, 2.01, 1.0)
    assert later.target == 0.0 and later.drive_speed == 0.0
    controller.set_cmd_vel(0.2, 0.0, 3.01)  # a new command after the reset is obeyed
    assert run(controller, 3.01, 0.5).drive_speed > 0.0
    with pytest.raises(ValueError, match='finite'):
        controller.reset(math.nan)


def test_a_command_between_a_reset_and_its_first_state_is_kept():
    controller = make(cmd_vel_timeout=0.0)
    controller.set_cmd_vel(0.2, 0.4, 0.0)
    run(controller, 0.0, 1.0)
    controller.reset(1.0)
    controller.set_cmd_vel(0.2, 0.0, 1.0)
    out = run(controller, 1.0, 0.5, measured=0.0)
    assert out.source == SOURCE_CMD_VEL and out.drive_speed > 0.0
