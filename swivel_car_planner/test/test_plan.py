"""Unit tests of the feasibility check and the plan against the model library."""

import dataclasses
import math

from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from swivel_car_model import climbing, dynamics, kinematics, planar
from swivel_car_model.params import SwivelCarParams

from swivel_car_planner.core import (
    ClimbRequest, ErrorCode, make_plan, PlanError, PlannerConfig, validate_request)
from swivel_car_planner.core.plan import (
    lead_angle, PROCEDURE_ACTIVE_LIFT, PROCEDURE_SEMI_ACTIVE)

P = SwivelCarParams()
CONFIG = PlannerConfig()
# make_plan without a whole-car limit checks the model's own limits only.
FRONT = CONFIG
# The standard lift wherever it can plan (the push-lift takes over from 24 cm by default).
STANDARD = dataclasses.replace(CONFIG, push_lift_height=0.3)
WHOLE_CAR_LIMIT = 0.08  # [m]
# Backing up straight only: the refusals the repositioning (test_reposition.py) overcomes.
STRAIGHT = dataclasses.replace(CONFIG, max_reposition=0.0)


def request(height=0.05, distance=1.2, yaw=0.0, plan_only=False, width=0.0, offset=0.0):
    return ClimbRequest(step_height=height, step_distance=distance, step_yaw=yaw,
                        plan_only=plan_only, step_width=width, step_offset=offset)


def refusal(p=P, config=CONFIG, whole_car_limit=math.inf, **kwargs):
    with pytest.raises(PlanError) as caught:
        make_plan(p, config, request(**kwargs), whole_car_limit)
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
    assert plan.peak_torque <= P.swivel_torque_limit
    peak, energy = dynamics.climb_torque_energy(P, 0.05, CONFIG.swivel_rate)
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


def test_step_above_the_measured_whole_car_limit_is_refused_with_the_limit():
    error = refusal(height=WHOLE_CAR_LIMIT + 0.01, whole_car_limit=WHOLE_CAR_LIMIT)
    assert error.code == ErrorCode.UNREACHABLE_HEIGHT
    assert 'whole car' in error.message and f'{WHOLE_CAR_LIMIT:.3f} m' in error.message
    assert make_plan(P, CONFIG, request(WHOLE_CAR_LIMIT), WHOLE_CAR_LIMIT).swivel_angle > 0.0
    assert make_plan(P, FRONT, request(WHOLE_CAR_LIMIT + 0.01)).swivel_angle > 0.0


def test_plan_only_makes_exactly_the_checks_of_a_real_call():
    no_backup = dataclasses.replace(STRAIGHT, max_backup=0.0)
    for kwargs in ({'height': WHOLE_CAR_LIMIT + 0.01}, {'distance': 0.1, 'config': no_backup},
                   {'width': 0.3}):
        real = refusal(whole_car_limit=WHOLE_CAR_LIMIT, **kwargs)
        planned = refusal(whole_car_limit=WHOLE_CAR_LIMIT, plan_only=True, **kwargs)
        assert (planned.code, planned.message) == (real.code, real.message)


def test_approach_accounts_for_the_drift_of_the_lift():
    plan = make_plan(P, FRONT, request(0.15))
    _, _, drift_yaw = dynamics.swivel_pose_drift(P, 0.0, plan.swivel_angle)
    assert plan.approach_heading == pytest.approx(
        plan.lead_angle - plan.advance_turn - drift_yaw)
    assert plan.lead_distance >= P.r + CONFIG.lift_gap
    axle_normal = plan.approach_distance * math.cos(plan.approach_heading)
    assert axle_normal == pytest.approx(
        plan.lead_distance + P.h * abs(math.sin(plan.approach_heading)))


def drive_arc(plan, steps=2000):
    """
    Euler-integrate base_link along the plan's advance from its heading once the wheel is up.

    At the model's curvature; returns the front wheels' rest points' normal coordinates,
    relative to the start, along the way [m].
    """
    curvature = planar.curvature_for_swivel(P, plan.swivel_angle)
    heading = plan.lead_angle - plan.advance_turn
    ds = plan.advance_length / steps
    x, lifted, other = 0.0, [], []
    for _ in range(steps + 1):
        for side, out in ((plan.lifted_side, lifted), (-plan.lifted_side, other)):
            out.append(x + P.wheelbase * math.cos(heading) - side * P.h * math.sin(heading))
        x += ds * math.cos(heading + curvature * ds / 2.0)
        heading += curvature * ds
    return heading - curvature * ds, np.array(lifted), np.array(other)


@pytest.mark.parametrize('height', [0.05, 0.15, 0.25, 0.26])
def test_the_advance_arc_takes_the_lifted_wheel_over_the_edge_clear_of_the_other(height):
    plan = make_plan(P, STANDARD, request(height))
    end_heading, lifted, other = drive_arc(plan)
    assert end_heading == pytest.approx(plan.lead_angle, abs=1e-6)
    start = -plan.lead_distance  # [m] the lifted wheel's contact to the edge at lift
    assert lifted[-1] - lifted[0] == pytest.approx(plan.lead_distance + CONFIG.lead_margin,
                                                   abs=1e-4)
    reach = min(height, P.r)  # [m] a wheel meets an edge at least r high at r from it
    other_edge = other - other[0] + start + 2.0 * plan.lifted_side * P.h * math.sin(
        plan.lead_angle - plan.advance_turn)
    assert np.max(other_edge) <= -(reach + CONFIG.lead_margin) + 1e-3


def test_a_tight_advance_arc_is_planned_as_one():
    """
    Check a tight advance arc is planned as one.

    At 26 cm the swivel is held at 1.24 rad: a 0.49 m radius, and the lift alone turns the
    car 0.37 rad. The arc ends more oblique than the straight-line lead angle (the other
    wheel swings towards the riser on the way) and the approach leads with the other wheel.
    At 27 cm (1.37 rad, 0.28 m) no heading keeps the other wheel off the riser.
    """
    plan = make_plan(P, STANDARD, request(0.26))
    assert not plan.push_lift
    assert abs(plan.swivel_angle) <= P.swivel_limit
    assert abs(plan.lead_angle) > lead_angle(P, CONFIG, 0.26) + 0.1
    assert abs(plan.advance_turn) > 0.3
    assert plan.lifted_side * plan.approach_heading > 0.0
    assert make_plan(P, FRONT, request(0.27, distance=3.0)).push_lift


def test_where_no_heading_keeps_the_other_wheel_off_the_riser_the_grounded_one_leads():
    """
    Check the grounded wheel leads where no heading keeps the other wheel off the riser.

    The push-lift (docs/climbing_design.md, "The front wheels"): at 27 cm the approach
    turns the other way, the grounded wheel stops push_gap short of the riser and the lifted
    one trails it by 2 h sin(push_lead).
    """
    plan = make_plan(P, FRONT, request(0.27, distance=3.0))
    assert plan.push_lift
    assert plan.swivel_angle == pytest.approx(P.swivel_limit * plan.lifted_side)
    assert plan.wheel_clearance > CONFIG.clearance_margin
    lead = CONFIG.push_lead
    assert plan.approach_heading == pytest.approx(plan.lifted_side * lead)
    grounded = plan.lead_distance - 2.0 * P.h * math.sin(lead)  # [m] its rest contact
    assert grounded == pytest.approx(
        P.r * math.cos(lead) + P.wheel_width / 2.0 * math.sin(lead) + CONFIG.push_gap)
    axle_normal = plan.approach_distance * math.cos(plan.approach_heading)
    assert axle_normal == pytest.approx(plan.lead_distance - P.h * math.sin(lead))
    _, _, drift_yaw = dynamics.swivel_pose_drift(P, 0.0, plan.swivel_angle)
    assert plan.lead_angle == pytest.approx(
        plan.approach_heading + drift_yaw + plan.advance_turn)


def lowest_rim_point(centre, axle, samples=20000):
    """Return the lowest of ``samples`` points on a wheel's rim, by brute force [m]."""
    axle = axle / np.linalg.norm(axle)
    u = np.cross(axle, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    v = np.cross(axle, u)
    angles = np.linspace(0.0, 2.0 * math.pi, samples)
    rim = centre + P.r * (np.outer(np.cos(angles), u) + np.outer(np.sin(angles), v))
    return rim[np.argmin(rim[:, 2])]


@pytest.mark.parametrize('swivel', [1.0, 1.37, -1.37])
def test_the_lifted_wheels_lowest_point_is_where_its_rim_is_lowest(swivel):
    frames = kinematics.forward_kinematics(P, swivel)
    right, left = frames.o3[:3, 3], frames.o3_left[:3, 3]
    lifted, grounded = (left, right) if swivel > 0 else (right, left)
    low = lowest_rim_point(lifted, left - right)
    ground = lowest_rim_point(grounded, left - right)
    assert (low[0], low[1]) == pytest.approx(
        tuple(climbing.lifted_wheel_lowest_point(P, swivel)[:2]), abs=1e-4)
    assert low[2] - ground[2] == pytest.approx(
        kinematics.lifted_wheel_lowest_height(P, swivel), abs=1e-4)
    # Near the swivel limit the lifted wheel is ahead of the grounded wheel's contact.
    if abs(swivel) > 1.3:
        assert low[0] > float(kinematics.contact_point(P, swivel)[0]) + 0.08


def test_the_push_advance_takes_the_lifted_wheel_over_before_the_grounded_one_meets_the_riser():
    """
    Check the push advance takes the lifted wheel over before the grounded one meets the riser.

    Euler-integrate base_link on the arc from the lift, independently of the plan's closed
    form: the lifted wheel's lowest point ends push_margin past the edge, the grounded wheel's
    contact never passes the riser.
    """
    plan = make_plan(P, FRONT, request(0.27, distance=3.0))
    curvature = planar.curvature_for_swivel(P, plan.swivel_angle)
    heading = plan.lead_angle - plan.advance_turn
    steps = 2000
    ds = plan.advance_length / steps
    # base_link along the normal at the lift, from the lifted wheel's rest contact
    x = (-plan.lead_distance - P.wheelbase * math.cos(plan.approach_heading)
         + plan.lifted_side * P.h * math.sin(plan.approach_heading))
    contact = [float(v) for v in kinematics.contact_point(P, plan.swivel_angle)]
    lifted, grounded = [], []
    for _ in range(steps + 1):
        for (bx, by), out in ((plan.lifted_point, lifted), (contact, grounded)):
            out.append(x + bx * math.cos(heading) - by * math.sin(heading))
        x += ds * math.cos(heading + curvature * ds / 2.0)
        heading += curvature * ds
    # The plan takes the first of its 400 arc samples (1.9 mm of base_link's path apart
    # here) that puts the landing point push_margin over the edge: it ends up to one
    # sample's advance past it, 1.7 mm here (this Euler walk: 1e-10 m from 100x the steps).
    assert lifted[-1] == pytest.approx(CONFIG.push_margin, abs=2e-3)
    assert max(grounded) <= 0.0


def test_a_push_lift_that_cannot_get_over_says_why():
    error = refusal(config=dataclasses.replace(CONFIG, push_gap=0.3), height=0.27,
                    distance=3.0)
    assert error.code == ErrorCode.WHEEL_INTERFERENCE and 'push_lead' in error.message


def test_a_step_beyond_the_swivel_limit_is_refused_with_it():
    error = refusal(p=dataclasses.replace(P, swivel_limit=1.2), height=0.26)
    assert error.code == ErrorCode.UNREACHABLE_HEIGHT and 'swivel_limit' in error.message


def test_step_beyond_reach_is_unreachable():
    reach, _ = kinematics.max_scalable_step(P, respect_tip_over=False)
    error = refusal(config=FRONT, height=reach + 0.01)
    assert error.code == ErrorCode.UNREACHABLE_HEIGHT
    assert 'reach' in error.message


def test_tip_over_margin_refuses_a_plan_that_would_pitch_too_far():
    error = refusal(config=dataclasses.replace(FRONT, tip_over_margin=1.0), height=0.05)
    assert error.code == ErrorCode.TIP_OVER


def test_torque_limit_refuses_a_plan_the_actuator_cannot_do():
    error = refusal(p=dataclasses.replace(P, swivel_torque_limit=0.01), height=0.05)
    assert error.code == ErrorCode.TORQUE_LIMIT
    assert 'N m' in error.message


def test_wheel_interference_refuses_a_long_shaft_on_a_short_body():
    # Long shafts on short columns: at a 2 cm step the steering wheel's shaft reaches back
    # over the rear axle (eq. 75 margin about -0.07 m) while the tip-over rule still holds.
    p = SwivelCarParams(l=0.05, h=0.3, r=0.03, phi=1.4, wheel_width=0.02,
                        swivel_torque_limit=1e6)
    error = refusal(p=p, height=0.02,
                    distance=3.0)
    assert error.code == ErrorCode.WHEEL_INTERFERENCE
    assert 'eq. 75' in error.message


def test_step_too_close_to_align_is_invalid_without_room_to_back_up():
    error = refusal(config=dataclasses.replace(STRAIGHT, max_backup=0.0), height=0.05,
                    distance=0.1)
    assert error.code == ErrorCode.INVALID_REQUEST
    assert 'too close' in error.message
    error = refusal(config=dataclasses.replace(STRAIGHT, max_backup=0.2), height=0.05,
                    distance=0.1, yaw=0.5)
    assert 'too close' in error.message and 'max_backup' in error.message


def test_a_refusal_after_backing_up_says_what_still_stands_in_the_way():
    # Straight at a face centred on the car: backing up makes room to turn, but the single
    # turn onto the lead angle then crosses the edge beside the face.
    error = refusal(config=STRAIGHT, height=0.05, distance=0.6, width=1.6)
    assert error.code == ErrorCode.INVALID_REQUEST
    first, _, then = error.message.partition('max_backup')
    assert 'aligning to' in first and 'beside the top face' in then


@pytest.mark.parametrize('yaw, width', [(0.0, 0.0), (0.3, 0.0), (-0.3, 2.0)])
def test_a_close_step_is_planned_from_the_least_backup_that_makes_room(yaw, width):
    near = make_plan(P, CONFIG, request(0.05, distance=0.2, yaw=yaw, width=width))
    assert 0.0 < near.backup_distance <= CONFIG.max_backup
    # The plan is the one of the same step asked from where the backup ends...
    backed = make_plan(P, CONFIG, request(0.05, distance=0.2 + near.backup_distance,
                                          yaw=yaw, width=width))
    assert backed.backup_distance == 0.0
    assert (backed.approach_heading, backed.crossing) == (near.approach_heading, near.crossing)
    # ...and one increment less would not do.
    shorter = near.backup_distance - 0.05
    with pytest.raises(PlanError, match='too close'):
        make_plan(P, dataclasses.replace(STRAIGHT, max_backup=0.0),
                  request(0.05, distance=0.2 + shorter, yaw=yaw, width=width))


def test_without_a_width_the_approach_only_holds_its_heading():
    assert make_plan(P, CONFIG, request(0.05)).crossing is None


@pytest.mark.parametrize('height', [0.03, 0.05, 0.07])
@pytest.mark.parametrize('yaw', [-0.2, 0.0, 0.2])
def test_on_a_wide_face_the_crossing_is_where_turning_at_once_on_the_aligning_arc_leads(
        height, yaw):
    # Planned on an instant turn, the line lay beside where the car's turn ends (8.8 cm for
    # 5 cm at 1 m, square): the approach chased it into the lift point, up to max_steer off
    # its heading, and met the lift point off the heading on a loaded machine.
    distance = 1.0  # [m] front axle to the edge along x, as the hardware-time test asks
    plan = make_plan(P, STANDARD, request(height, distance=distance, yaw=yaw, width=4.0))
    assert plan.procedure == PROCEDURE_ACTIVE_LIFT and plan.backup_distance == 0.0
    assert plan.reposition == ()
    # The car's frame: base_link (the rear axle) at the origin, heading along x; the edge
    # through (wheelbase + distance, 0) with its normal at ``yaw``. base_link turns on the
    # aligning arc (radius wheelbase / tan(max_steer)) to the approach heading, then straight.
    radius = P.wheelbase / math.tan(STANDARD.max_steer)  # [m]
    final = yaw + plan.approach_heading  # [rad] in the car's frame
    side = math.copysign(1.0, final)
    start = np.array([radius * math.sin(abs(final)), side * radius * (1.0 - math.cos(final))])
    edge_point = np.array([P.wheelbase + distance, 0.0])
    normal = np.array([math.cos(yaw), math.sin(yaw)])
    direction = np.array([math.cos(final), math.sin(final)])
    crossing = start + direction * (normal @ (edge_point - start)) / (normal @ direction)
    along = (crossing - edge_point) @ np.array([-math.sin(yaw), math.cos(yaw)])  # leftwards
    assert plan.crossing == pytest.approx(along, abs=1e-9)  # closed forms, both


@pytest.mark.parametrize('yaw, offset', [(0.0, -0.6), (0.3, -0.6), (-0.3, 0.6), (0.0, -1.0)])
def test_the_crossing_keeps_every_wheel_on_the_top_face(yaw, offset):
    width = 1.5
    plan = make_plan(P, CONFIG, request(0.05, distance=2.5, yaw=yaw, width=width,
                                        offset=offset))
    psi = plan.lead_angle
    # The wheels' contacts while on top, from the rear axle at the crossing to the front
    # axle once the trailing rear wheel is rest_margin past the edge.
    reach = (CONFIG.rest_margin + P.h * abs(math.sin(psi))) / math.cos(psi) + P.wheelbase
    for along_heading in (0.0, reach):
        for side in (-1.0, 1.0):
            along = (plan.crossing + along_heading * math.sin(psi)
                     + side * (P.h * math.cos(psi) + P.wheel_width / 2.0))
            assert offset - width / 2.0 + CONFIG.edge_margin - 1e-9 <= along
            assert along <= offset + width / 2.0 - CONFIG.edge_margin + 1e-9


def test_a_face_the_approach_cannot_reach_is_refused_as_too_close():
    error = refusal(config=STRAIGHT, height=0.05, distance=1.0, width=1.5, offset=2.5)
    assert error.code == ErrorCode.INVALID_REQUEST
    assert 'beside the top face' in error.message


def test_a_face_narrower_than_the_car_needs_is_refused():
    error = refusal(height=0.05, width=0.45)
    assert error.code == ErrorCode.INVALID_REQUEST
    assert 'too narrow' in error.message


def test_bad_extent_is_an_invalid_request():
    assert validate_request(request(width=-1.0), CONFIG)[0] == ErrorCode.INVALID_REQUEST
    assert validate_request(request(offset=math.nan), CONFIG)[0] == ErrorCode.INVALID_REQUEST
    assert validate_request(request(offset=99.0), CONFIG)[0] == ErrorCode.INVALID_REQUEST


@settings(max_examples=30)
@given(st.floats(0.005, 0.3), st.floats(-1.0, 1.0))
def test_every_plan_keeps_its_margins_or_says_why_not(height, yaw):
    try:
        plan = make_plan(P, FRONT, request(height, distance=3.0, yaw=yaw))
    except PlanError as error:
        assert error.code in (ErrorCode.UNREACHABLE_HEIGHT, ErrorCode.TIP_OVER,
                              ErrorCode.TORQUE_LIMIT, ErrorCode.WHEEL_INTERFERENCE,
                              ErrorCode.INVALID_REQUEST)
        assert error.message
        return
    assert plan.wheel_clearance >= FRONT.clearance_margin - 1e-9
    assert plan.tip_over_margin >= FRONT.tip_over_margin
    assert plan.peak_torque <= P.swivel_torque_limit
    assert math.isfinite(plan.duration) and plan.duration > 0.0
    assert plan.lifted_side * plan.swivel_angle > 0.0
    if not plan.push_lift:  # the push-lift checks the wheels' positions at the lift angle
        assert abs(plan.lead_angle) >= climbing.min_approach_angle_for_step(P, height) - 1e-12


def test_negative_phi_plans_the_semi_active_procedure():
    p = SwivelCarParams(phi=-math.pi / 3)
    plan = make_plan(p, CONFIG, request(0.04, distance=2.0))
    assert plan.procedure == PROCEDURE_SEMI_ACTIVE
    assert abs(plan.lead_angle) >= climbing.min_approach_angle_for_step(p, 0.04)
