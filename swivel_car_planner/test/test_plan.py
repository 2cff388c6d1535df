"""Unit tests of the feasibility check and the plan against the model library."""

import dataclasses
import math

from hypothesis import given, settings, strategies as st
import pytest
from swivel_car_model import climbing, dynamics, kinematics
from swivel_car_model.params import SwivelCarParams

from swivel_car_planner.core import ClimbRequest, ErrorCode, PlanError, PlannerConfig, make_plan
from swivel_car_planner.core.plan import (
    lead_angle, PROCEDURE_ACTIVE_LIFT, PROCEDURE_SEMI_ACTIVE)

P = SwivelCarParams()
CONFIG = PlannerConfig()
# The planner without the rear axle's traction limit: the model's own limits only.
FRONT = dataclasses.replace(CONFIG, rear_step_limit=1.0)


def request(height=0.05, distance=1.2, yaw=0.0, plan_only=False):
    return ClimbRequest(step_height=height, step_distance=distance, step_yaw=yaw,
                        plan_only=plan_only)


def refusal(p=P, config=CONFIG, **kwargs):
    with pytest.raises(PlanError) as caught:
        make_plan(p, config, request(**kwargs))
    return caught.value


def test_feasible_plan_clears_the_step_and_keeps_the_rules():
    plan = make_plan(P, FRONT, request(0.05))
    assert plan.procedure == PROCEDURE_ACTIVE_LIFT
    assert plan.wheel_clearance >= CONFIG.clearance_margin - 1e-9
    assert kinematics.lifted_wheel_lowest_height(P, plan.swivel_angle) == pytest.approx(
        0.05 + plan.wheel_clearance)
    assert plan.lift_angle == pytest.approx(kinematics.lift_angle(P, plan.swivel_angle))
    assert plan.tip_over_margin >= CONFIG.tip_over_margin
    assert plan.interference_margin > 0.0
    assert plan.peak_torque <= CONFIG.torque_limit
    peak, energy = dynamics.climb_torque_energy(P, 0.05)
    assert (plan.peak_torque, plan.energy) == pytest.approx((peak, energy))
    assert plan.duration > 0.0
    assert plan.max_scalable_step == pytest.approx(kinematics.max_scalable_step(P)[0])


def test_swivel_angle_is_the_smallest_that_clears():
    plan = make_plan(P, FRONT, request(0.05))
    smaller = abs(plan.swivel_angle) - 0.01
    assert kinematics.lifted_wheel_lowest_height(P, smaller) < 0.05 + CONFIG.clearance_margin


def test_square_step_lifts_the_left_wheel_and_turns_right_to_lead_with_it():
    plan = make_plan(P, FRONT, request(0.05, yaw=0.0))
    assert plan.lifted_side == 1 and plan.swivel_angle > 0.0
    assert plan.lead_angle < 0.0


def test_step_yawed_the_other_way_lifts_the_right_wheel():
    plan = make_plan(P, FRONT, request(0.05, yaw=-0.3))
    assert plan.lifted_side == -1 and plan.swivel_angle < 0.0
    assert plan.lead_angle > 0.0


def test_lead_angle_puts_the_lifted_wheel_over_before_the_other_meets_the_riser():
    for height in (0.02, 0.05, 0.1):
        psi = lead_angle(P, CONFIG, height)
        reach = math.sqrt(P.r ** 2 - (P.r - min(height, P.r)) ** 2)
        assert 2.0 * P.h * math.sin(psi) == pytest.approx(reach + 2.0 * CONFIG.lead_margin)


def test_second_wheel_swivel_lifts_it_by_the_clearance_on_the_other_side():
    plan = make_plan(P, FRONT, request(0.05))
    assert plan.second_swivel_angle < 0.0 < plan.swivel_angle
    assert kinematics.lifted_wheel_lowest_height(P, plan.second_swivel_angle) == pytest.approx(
        CONFIG.clearance_margin)


def test_step_above_the_rear_axle_limit_is_unreachable_for_the_whole_car():
    error = refusal(height=CONFIG.rear_step_limit + 0.01)
    assert error.code == ErrorCode.UNREACHABLE_HEIGHT
    assert 'rear axle' in error.message
    assert make_plan(P, FRONT, request(CONFIG.rear_step_limit + 0.01)).swivel_angle > 0.0


def test_approach_accounts_for_the_drift_of_the_lift():
    plan = make_plan(P, FRONT, request(0.15))
    _, _, drift_yaw = dynamics.swivel_pose_drift(P, 0.0, plan.swivel_angle)
    assert plan.approach_heading == pytest.approx(plan.lead_angle - drift_yaw)
    assert plan.lead_distance >= P.r + CONFIG.lift_gap
    axle_normal = plan.approach_distance * math.cos(plan.approach_heading)
    assert axle_normal == pytest.approx(
        plan.lead_distance + P.h * abs(math.sin(plan.approach_heading)))


def test_step_beyond_reach_is_unreachable():
    reach, _ = kinematics.max_scalable_step(P, respect_tip_over=False)
    error = refusal(config=FRONT, height=reach + 0.01)
    assert error.code == ErrorCode.UNREACHABLE_HEIGHT
    assert 'reach' in error.message


def test_tip_over_margin_refuses_a_plan_that_would_pitch_too_far():
    error = refusal(config=dataclasses.replace(FRONT, tip_over_margin=1.0), height=0.05)
    assert error.code == ErrorCode.TIP_OVER


def test_torque_limit_refuses_a_plan_the_actuator_cannot_do():
    error = refusal(config=dataclasses.replace(FRONT, torque_limit=0.01), height=0.05)
    assert error.code == ErrorCode.TORQUE_LIMIT
    assert 'N m' in error.message


def test_wheel_interference_refuses_a_long_shaft_on_a_short_body():
    # Long shafts on short columns: at a 2 cm step the steering wheel's shaft reaches back
    # over the rear axle (eq. 75 margin about -0.07 m) while the tip-over rule still holds.
    p = SwivelCarParams(l=0.05, h=0.3, r=0.03, phi=1.4, wheel_width=0.02)
    error = refusal(p=p, config=dataclasses.replace(FRONT, torque_limit=1e6), height=0.02,
                    distance=3.0)
    assert error.code == ErrorCode.WHEEL_INTERFERENCE
    assert 'eq. 75' in error.message


def test_step_too_close_to_align_is_invalid_unless_plan_only():
    error = refusal(config=FRONT, height=0.05, distance=0.1)
    assert error.code == ErrorCode.INVALID_REQUEST
    assert 'too close' in error.message
    assert make_plan(P, FRONT, request(0.05, distance=0.1, plan_only=True)).swivel_angle > 0.0


@settings(max_examples=30, deadline=None)
@given(st.floats(0.005, 0.3), st.floats(-1.0, 1.0))
def test_every_plan_keeps_its_margins_or_says_why_not(height, yaw):
    try:
        plan = make_plan(P, FRONT, request(height, distance=3.0, yaw=yaw))
    except PlanError as error:
        assert error.code in (ErrorCode.UNREACHABLE_HEIGHT, ErrorCode.TIP_OVER,
                              ErrorCode.TORQUE_LIMIT, ErrorCode.INVALID_REQUEST)
        assert error.message
        return
    assert plan.wheel_clearance >= FRONT.clearance_margin - 1e-9
    assert plan.tip_over_margin >= FRONT.tip_over_margin
    assert plan.peak_torque <= FRONT.torque_limit
    assert math.isfinite(plan.duration) and plan.duration > 0.0
    assert plan.lifted_side * plan.swivel_angle > 0.0
    assert abs(plan.lead_angle) >= climbing.min_approach_angle_for_step(P, height) - 1e-12


def test_negative_phi_plans_the_semi_active_procedure():
    p = SwivelCarParams(phi=-math.pi / 3)
    plan = make_plan(p, CONFIG, request(0.04, distance=2.0))
    assert plan.procedure == PROCEDURE_SEMI_ACTIVE
    assert abs(plan.lead_angle) >= climbing.min_approach_angle_for_step(p, 0.04)
