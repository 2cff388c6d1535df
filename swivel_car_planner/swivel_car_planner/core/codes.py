"""
Error codes and climb phases, numerically equal to the constants of the ClimbStep interfaces.

Those are swivel_car_msgs/srv/ClimbStep and action/ClimbStep (a node test checks that they
agree).
"""

from enum import IntEnum


class ErrorCode(IntEnum):
    NONE = 0
    INVALID_REQUEST = 1
    BUSY = 2
    NOT_READY = 3
    UNREACHABLE_HEIGHT = 4
    TIP_OVER = 5
    WHEEL_INTERFERENCE = 6
    TORQUE_LIMIT = 7
    CANCELED = 8
    TIMEOUT = 9
    TIP_OVER_ABORT = 10
    STALL = 11
    NO_PROGRESS = 12
    FAILED = 13
    NO_STEP_DETECTED = 14


class Phase(IntEnum):
    PLANNING = 0
    APPROACH = 1
    LIFT = 2
    ADVANCE = 3
    SET_DOWN = 4
    CLIMB_REST = 5
    DONE = 6
    ABORTING = 7
