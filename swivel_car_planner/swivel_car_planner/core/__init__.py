"""
The planner's ROS-free core: request validation, feasibility and plan, climb state machine.

Nothing here imports rclpy; the node converts messages to and from these types.
"""

from swivel_car_planner.core.codes import ErrorCode, Phase
from swivel_car_planner.core.config import PlannerConfig
from swivel_car_planner.core.plan import ClimbPlan, make_plan, PlanError
from swivel_car_planner.core.request import ClimbRequest, validate_request
from swivel_car_planner.core.state_machine import (
    ClimbStateMachine, Command, Feedback, Observation, Outcome)

__all__ = [
    'ClimbPlan', 'ClimbRequest', 'ClimbStateMachine', 'Command', 'ErrorCode', 'Feedback',
    'Observation', 'Outcome', 'Phase', 'PlanError', 'PlannerConfig', 'make_plan',
    'validate_request',
]
