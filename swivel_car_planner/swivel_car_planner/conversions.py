"""Conversions between swivel_car_msgs and the planner core's types."""

from __future__ import annotations

from swivel_car_msgs.msg import ClimbOutcome, ClimbPlan as ClimbPlanMsg

from swivel_car_planner.core import ClimbPlan, ClimbRequest, Outcome


def request_from(message, with_time_allowance: bool) -> ClimbRequest:
    """Make a core request from a srv/ClimbStep request or an action/ClimbStep goal."""
    return ClimbRequest(
        step_height=float(message.step_height), step_distance=float(message.step_distance),
        step_yaw=float(message.step_yaw), plan_only=bool(message.plan_only),
        time_allowance=float(message.time_allowance) if with_time_allowance else 0.0,
        step_width=float(message.step_width), step_offset=float(message.step_offset))


def plan_to_msg(plan: ClimbPlan) -> ClimbPlanMsg:
    msg = ClimbPlanMsg()
    for name in ('swivel_angle', 'lift_angle', 'wheel_clearance', 'approach_distance',
                 'approach_heading', 'peak_torque', 'energy', 'max_scalable_step',
                 'tip_over_margin', 'interference_margin', 'duration'):
        setattr(msg, name, float(getattr(plan, name)))
    msg.procedure = int(plan.procedure)
    return msg


def outcome_to_msg(outcome: Outcome) -> ClimbOutcome:
    return ClimbOutcome(
        duration=float(outcome.duration), peak_torque=float(outcome.peak_torque),
        energy=float(outcome.energy), max_pitch=float(outcome.max_pitch),
        distance_travelled=float(outcome.distance_travelled))
