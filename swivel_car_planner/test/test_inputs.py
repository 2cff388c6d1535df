"""The planner's inputs: a non-finite field is refused where it enters, said rate-limited."""

import math

import pytest
from swivel_car_planner.core import inputs

QUATERNION = (0.0, 0.0, 0.0, 1.0)
ODOM = {'pose.pose.position.x': 0, 'pose.pose.position.y': 1,
        **{f'pose.pose.orientation.{axis}': (2, i) for i, axis in enumerate('xyzw')},
        'twist.twist.linear.x': 3}
IMU = {f'orientation.{axis}': (0, i) for i, axis in enumerate('xyzw')}
# controller_state_values' arguments: set point, torque, command stamp, swivel, swivel rate
CONTROLLER_STATE = {'set_point': 0, 'torque': 1, 'measured': 3, 'measured_rate': 4}


def _with(arguments, where, value):
    """Return ``arguments`` with the one at ``where`` (index, or index in a tuple) replaced."""
    arguments = list(arguments)
    if isinstance(where, tuple):
        index, item = where
        numbers = list(arguments[index])
        numbers[item] = value
        arguments[index] = tuple(numbers)
    else:
        arguments[where] = value
    return arguments


CASES = ([(inputs.odom_values, (1.0, 2.0, QUATERNION, 0.3), name, where)
          for name, where in ODOM.items()]
         + [(inputs.imu_values, (QUATERNION,), name, where) for name, where in IMU.items()]
         + [(inputs.controller_state_values, (0.1, 2.0, -math.inf, 0.1, 0.0), name, where)
            for name, where in CONTROLLER_STATE.items()])


@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize('values, arguments, name, where', CASES)
def test_a_non_finite_field_is_refused_by_name(values, arguments, name, where, bad):
    values(*arguments)  # finite: taken
    with pytest.raises(ValueError, match=rf'^{name} must be a finite number, got {bad}$'):
        values(*_with(arguments, where, bad))


def test_no_controller_command_heard_yet_is_no_bad_input():
    assert inputs.controller_state_values(0.1, 2.0, -math.inf, 0.1, 0.0)[2] == -math.inf


def test_refusals_are_said_once_per_interval_per_topic_with_how_many_were_held_back():
    log = inputs.RefusalLog(5.0)
    assert log.line('odom', 'x is nan', 10.0) == 'odom refused: x is nan: not acted on'
    assert log.line('odom', 'x is nan', 12.0) is None
    assert log.line('imu', 'y is inf', 12.0) == 'imu refused: y is inf: not acted on'
    assert log.line('odom', 'x is nan', 14.99) is None
    assert log.line('odom', 'x is nan', 15.0) == (
        'odom refused: x is nan: not acted on (2 more refused since the last line)')
    assert log.line('odom', 'x is nan', 20.0) == 'odom refused: x is nan: not acted on'
