"""
JointStateController: a jump of the joint_states stamps is acted on once confirmed.

The next message confirms it by following it; a single faulty stamp changes nothing (issue
12).
"""

import math

import pytest
from swivel_car_control.core.controller import ControllerConfig, SOURCE_CMD_VEL, SwivelController
from swivel_car_control.core.joint_states import (
    ImpossibleReading, JointStateController, LIMIT_SLACK, MAX_GAP, MAX_SWIVEL_RATE,
    UnconfirmedStamp)
from swivel_car_control.joints import MissingJointError
from swivel_car_model.params import SwivelCarParams

NAMES = ['swivel_joint']
PERIOD = 0.01  # [s]


def driving(t_end: float) -> JointStateController:
    """Return a controller driven by cmd_vel from 0 to ``t_end`` [s], one answer per period."""
    controller = JointStateController(SwivelController(SwivelCarParams(), ControllerConfig()),
                                      'swivel_joint')
    steps = round(t_end / PERIOD)
    for k in range(steps + 1):
        controller.core.set_cmd_vel(0.3, 0.0, k * PERIOD)
        controller.answer(k * PERIOD, NAMES, [0.0], [0.0])
    return controller


@pytest.mark.parametrize('bad', [0.0, 1.0, 5.0 - 0.02, 5.0 + MAX_GAP + 0.1, 2.0**31 - 1])
def test_one_stamp_back_or_far_ahead_is_not_acted_on_and_the_drive_goes_on(bad):
    controller = driving(5.0)
    before = controller.answer(5.0, NAMES, [0.0], [0.0])[1]
    with pytest.raises(UnconfirmedStamp, match='until the next message confirms'):
        controller.answer(bad, NAMES, [0.0], [0.0])
    after = controller.answer(5.0 + PERIOD, NAMES, [0.0], [0.0])[1]
    assert after.source == SOURCE_CMD_VEL  # the cmd_vel in force was kept
    assert after.v_out == pytest.approx(before.v_out)
    assert after.drive_speed == pytest.approx(before.drive_speed)


def test_an_unconfirmed_stamp_is_a_missing_reading_to_the_callers():
    controller = driving(1.0)
    with pytest.raises(MissingJointError):
        controller.answer(0.0, NAMES, [0.0], [0.0])


def test_a_restarted_sim_is_followed_from_its_second_state_without_the_old_commands():
    controller = driving(5.0)
    with pytest.raises(UnconfirmedStamp):
        controller.answer(0.0, NAMES, [0.0], [0.0])
    out = controller.answer(PERIOD, NAMES, [0.0], [0.0])[1]
    assert out.v_out == 0.0 and out.drive_speed == 0.0  # the old run's cmd_vel is dropped
    assert controller.last_time == PERIOD


def test_a_confirmed_leap_ahead_goes_on_from_there():
    controller = driving(1.0)
    with pytest.raises(UnconfirmedStamp):
        controller.answer(3.0, NAMES, [0.0], [0.0])
    controller.answer(3.0 + PERIOD, NAMES, [0.0], [0.0])
    assert controller.last_time == 3.0 + PERIOD


@pytest.mark.parametrize('t', [1.0, 1.0 + PERIOD, 1.0 + MAX_GAP])
def test_the_same_stamp_again_and_gaps_up_to_max_gap_are_acted_on(t):
    controller = driving(1.0)
    controller.answer(t, NAMES, [0.0], [0.0])
    assert controller.last_time == t


LIMIT = SwivelCarParams().max_swivel_angle  # [rad] the swivel's mechanical stop


@pytest.mark.parametrize('position,rate', [
    (-1e12, -1e12), (-1e12, 0.0), (0.0, 1e12), (LIMIT + LIMIT_SLACK + 0.01, 0.0),
    (0.0, -MAX_SWIVEL_RATE * 1.01), (0.0, math.inf)])
def test_a_driver_glitch_is_refused_naming_the_joint_and_steps_nothing(position, rate):
    # The fuzz run's glitch (-1e12 once) kicked the PID to full torque for a cycle, unsaid.
    glitched, clean = driving(1.0), driving(1.0)
    with pytest.raises(ImpossibleReading, match="'swivel_joint'.*driver glitch"):
        glitched.answer(1.0 + PERIOD / 2, NAMES, [position], [rate])
    after = glitched.answer(1.0 + PERIOD, NAMES, [0.01], [0.1])[1]
    assert after == clean.answer(1.0 + PERIOD, NAMES, [0.01], [0.1])[1]


def test_readings_within_the_stop_s_slack_and_the_rate_limit_pass():
    controller = driving(1.0)
    controller.answer(1.0 + PERIOD, NAMES, [LIMIT + LIMIT_SLACK], [MAX_SWIVEL_RATE])
