"""A climb request and its validation (before any model call)."""

from __future__ import annotations

from dataclasses import dataclass

from swivel_car_model.checks import check_finite_number
from swivel_car_planner.core.codes import ErrorCode
from swivel_car_planner.core.config import PlannerConfig


@dataclass(frozen=True)
class ClimbRequest:
    """
    The fields of srv/ClimbStep and action/ClimbStep's goal.

    step_height : height of the step. # [m]
    step_distance : front axle ground contact to the edge along base_link x. # [m]
    step_yaw : the edge's angle to base_link's y axis. # [rad]
    time_allowance : climb time limit, 0 = the planner's default. # [s]
    step_width : extent of the step's top face along its edge; 0 = not known (wide enough:
        the approach only holds its heading). # [m]
    step_offset : the face's centre along the edge, leftwards from where base_link's x axis
        meets the edge. # [m]
    """

    step_height: float  # [m]
    step_distance: float  # [m]
    step_yaw: float  # [rad]
    plan_only: bool = False
    time_allowance: float = 0.0  # [s]
    step_width: float = 0.0  # [m]
    step_offset: float = 0.0  # [m]


def validate_request(request: ClimbRequest,
                     config: PlannerConfig) -> tuple[ErrorCode, str]:
    """
    Check a request's fields; ``(ErrorCode.NONE, '')`` when it is well formed.

    Returns
    -------
    (code, message)
        ``ErrorCode.INVALID_REQUEST`` and a message naming the first bad field.

    """
    for name in ('step_height', 'step_distance', 'step_yaw', 'time_allowance', 'step_width',
                 'step_offset'):
        try:
            check_finite_number(name, getattr(request, name))
        except ValueError as error:
            return ErrorCode.INVALID_REQUEST, str(error)
    if request.step_height <= 0.0:
        return (ErrorCode.INVALID_REQUEST,
                f'step_height must be > 0, got {request.step_height!r} m')
    if not 0.0 <= request.step_distance <= config.max_step_distance:
        return (ErrorCode.INVALID_REQUEST,
                f'step_distance must be in [0, {config.max_step_distance}] m, '
                f'got {request.step_distance!r} m')
    if abs(request.step_yaw) > config.max_step_yaw:
        return (ErrorCode.INVALID_REQUEST,
                f'|step_yaw| must be <= {config.max_step_yaw} rad, got {request.step_yaw!r} rad')
    if request.step_width < 0.0:
        return (ErrorCode.INVALID_REQUEST,
                f'step_width must be >= 0 (0 = not known), got {request.step_width!r} m')
    if abs(request.step_offset) > config.max_step_distance:
        return (ErrorCode.INVALID_REQUEST,
                f'|step_offset| must be <= {config.max_step_distance} m, '
                f'got {request.step_offset!r} m')
    if request.time_allowance < 0.0:
        return (ErrorCode.INVALID_REQUEST,
                f'time_allowance must be >= 0 (0 = default), got {request.time_allowance!r} s')
    return ErrorCode.NONE, ''
