"""
The control cores' input checks, as properties (issue 12).

A bad value (not finite, not a number, out of range) is refused with one ValueError naming
the field, and nothing changes; a good one is accepted.
"""

from dataclasses import fields, replace
import math

from bad_values import assert_refusal_names, at_most, NON_FINITE, NOT_A_FINITE_NUMBER, NOT_NUMERIC
from hypothesis import given, strategies as st
import pytest
from swivel_car_control.core.controller import ControllerConfig, SwivelController
from swivel_car_control.core.joint_states import JointStateOdometry
from swivel_car_control.core.limits import SlewLimiter
from swivel_car_control.core.odometry_input import JointStateGate
from swivel_car_control.core.pid import PidConfig, SwivelPid
from swivel_car_control.core.steering import SteeringMap, tip_safe_swivel_limit
from swivel_car_control.joints import JointReader
from swivel_car_model.description import CarDescription

P = CarDescription().model_params()
CONFIG_FIELDS = [item.name for item in fields(ControllerConfig)]
# Fields that may be 0 (a timeout 0 disables its deadman).
MAY_BE_ZERO = ('cmd_vel_timeout', 'swivel_command_timeout', 'slowdown_start',
               'tip_over_margin', 'max_integral_torque')
NAMES = ('swivel_joint', 'rear_left_wheel_joint', 'rear_right_wheel_joint')
GOOD_PID = {'kp': 1.0, 'ki': 1.0, 'kd': 1.0, 'max_torque': 1.0, 'max_integral_torque': 1.0}


@given(name=st.sampled_from(CONFIG_FIELDS), bad=NOT_A_FINITE_NUMBER | at_most(-1e-9))
def test_controller_config_refuses_a_bad_field_naming_it(name, bad):
    with pytest.raises(ValueError) as error:
        ControllerConfig(**{name: bad})
    assert_refusal_names(error.value, name)


@given(name=st.sampled_from([n for n in CONFIG_FIELDS if n not in MAY_BE_ZERO]))
def test_controller_config_refuses_a_zero_limit_naming_it(name):
    with pytest.raises(ValueError) as error:
        ControllerConfig(**{name: 0.0})
    assert_refusal_names(error.value, name)


@given(live=st.fixed_dictionaries({
    'cmd_vel_timeout': st.floats(0.0, 10.0), 'swivel_command_timeout': st.floats(0.0, 10.0),
    'slowdown_start': st.floats(0.0, 0.6)}), bad=NOT_A_FINITE_NUMBER,
    name=st.sampled_from(ControllerConfig.LIVE))
def test_a_controller_takes_good_live_values_and_keeps_its_config_on_a_bad_one(live, bad, name):
    controller = SwivelController(P, ControllerConfig())
    good = replace(ControllerConfig(), **live)
    controller.reconfigure(good)
    assert controller.config == good
    with pytest.raises(ValueError) as error:
        controller.reconfigure(replace(good, **{name: bad}))
    assert_refusal_names(error.value, name)
    assert controller.config == good


@given(slot=st.integers(0, 3), bad=NON_FINITE)
def test_a_bad_swivel_command_is_refused_naming_the_field_and_the_last_one_stays(slot, bad):
    controller = SwivelController(P, ControllerConfig())
    controller.set_swivel_command(0.2, 0.5, 3.0, True, 1.0)
    held = controller.swivel_command
    values = [0.1, 0.5, 2.0, 1.5]
    values[slot] = bad
    with pytest.raises(ValueError) as error:
        controller.set_swivel_command(*values[:3], True, values[3])
    assert_refusal_names(error.value, ('angle', 'max_rate', 'drive_speed', 'stamp')[slot])
    assert controller.swivel_command == held


@given(bad=st.floats(P.swivel_limit, 1e3, exclude_min=True).flatmap(
    lambda v: st.sampled_from([v, -v])) | at_most(-1e-9).map(lambda v: ('max_rate', v)))
def test_a_swivel_command_out_of_range_is_refused_and_the_last_one_stays(bad):
    controller = SwivelController(P, ControllerConfig())
    controller.set_swivel_command(0.2, 0.5, 3.0, True, 1.0)
    held = controller.swivel_command
    name, angle, max_rate = ('max_rate', 0.1, bad[1]) if isinstance(bad, tuple) else (
        'angle', bad, 0.5)
    with pytest.raises(ValueError) as error:
        controller.set_swivel_command(angle, max_rate, 1.0, True, 2.0)
    assert_refusal_names(error.value, name)
    assert controller.swivel_command == held


@given(angle=st.floats(-0.3, 0.3), max_rate=st.floats(0.0, 5.0), drive=st.floats(-20, 20),
       stamp=st.floats(-1e9, 1e9))
def test_a_good_swivel_command_is_taken(angle, max_rate, drive, stamp):
    controller = SwivelController(P, ControllerConfig())
    controller.set_swivel_command(angle, max_rate, drive, True, stamp)
    command = controller.swivel_command
    assert (command.angle, command.max_rate, command.drive_speed) == (angle, max_rate, drive)


@given(name=st.sampled_from(list(GOOD_PID) + ['integral_band']),
       bad=NOT_A_FINITE_NUMBER | at_most(-1e-9))
def test_pid_config_refuses_a_bad_field_naming_it(name, bad):
    if name == 'integral_band' and bad == math.inf:
        bad = 0.0  # inf: integrate at any error (the default)
    with pytest.raises(ValueError) as error:
        PidConfig(**{**GOOD_PID, name: bad})
    assert_refusal_names(error.value, name)


@given(slot=st.integers(0, 3), bad=NON_FINITE | at_most(-1e-9).map(lambda v: ('dt', v)))
def test_a_pid_step_with_a_bad_input_is_refused_and_keeps_its_memory(slot, bad):
    pid = SwivelPid(PidConfig(**GOOD_PID))
    pid.step(0.3, 0.0, 0.0, 0.01)
    memory = vars(pid).copy()
    values = [0.3, 0.1, 0.0, 0.01]
    names = ('set_point', 'measured', 'measured_rate', 'dt')
    if isinstance(bad, tuple):
        slot, bad = 3, bad[1]
    values[slot] = bad
    with pytest.raises(ValueError) as error:
        pid.step(*values)
    assert_refusal_names(error.value, names[slot])
    assert vars(pid) == memory


@given(name=st.sampled_from(['max_value', 'max_rate']),
       bad=st.just(math.nan) | at_most(0.0) | NOT_NUMERIC | st.booleans())
def test_slew_limiter_refuses_a_bad_limit_naming_it(name, bad):
    with pytest.raises(ValueError) as error:
        SlewLimiter(**{'max_value': 1.0, 'max_rate': 1.0, name: bad})
    assert_refusal_names(error.value, name)


# max_rate=None is no override.
@given(bad=st.just(math.nan) | at_most(-1e-9) | st.sampled_from(['1.0', [1.0]]) | st.booleans(),
       target=st.floats(-2.0, 2.0))
def test_a_slew_limiter_step_with_a_bad_rate_override_is_refused_and_keeps_its_value(
        bad, target):
    limiter = SlewLimiter(1.0, 1.0, initial=0.25)
    with pytest.raises(ValueError) as error:
        limiter.step(target, 0.1, max_rate=bad)
    assert_refusal_names(error.value, 'max_rate')
    assert limiter.value == 0.25


@given(bad=NOT_A_FINITE_NUMBER | st.booleans())
def test_a_slew_limiter_refuses_a_bad_target_naming_it(bad):
    limiter = SlewLimiter(1.0, 1.0, initial=0.25)
    with pytest.raises(ValueError) as error:
        limiter.step(bad, 0.1)
    assert_refusal_names(error.value, 'target')
    assert limiter.value == 0.25


@given(bad=NON_FINITE | at_most(-1e-9), target=st.floats(-2.0, 2.0))
def test_a_slew_limiter_step_with_a_bad_dt_is_refused_and_keeps_its_value(bad, target):
    limiter = SlewLimiter(1.0, 1.0, initial=0.25)
    with pytest.raises(ValueError) as error:
        limiter.step(target, bad)
    assert_refusal_names(error.value, 'dt')
    assert limiter.value == 0.25


@given(name=st.sampled_from(['publish_rate', 'yaw_rate_source']),
       bad=NOT_A_FINITE_NUMBER | at_most(0.0))
def test_joint_state_odometry_refuses_a_bad_setting_naming_it(name, bad):
    settings = {'publish_rate': 50.0, 'yaw_rate_source': 'swivel', name: bad}
    with pytest.raises(ValueError) as error:
        JointStateOdometry(P, *NAMES, **settings)
    assert_refusal_names(error.value, name)


@given(rate=st.floats(0.1, 1e4), source=st.sampled_from(['swivel', 'rear_wheels']))
def test_joint_state_odometry_takes_good_settings(rate, source):
    JointStateOdometry(P, *NAMES, yaw_rate_source=source, publish_rate=rate)


@given(joint=st.sampled_from(NAMES), bad=NOT_A_FINITE_NUMBER | at_most(0.0))
def test_joint_state_gate_refuses_a_bad_rate_limit_naming_the_joint(joint, bad):
    with pytest.raises(ValueError) as error:
        JointStateGate({**dict.fromkeys(NAMES, 100.0), joint: bad})
    assert_refusal_names(error.value, joint)


@given(bad=NOT_A_FINITE_NUMBER | at_most(0.0))
def test_joint_state_gate_refuses_a_bad_max_gap(bad):
    with pytest.raises(ValueError) as error:
        JointStateGate(dict.fromkeys(NAMES, 100.0), max_gap=bad)
    assert_refusal_names(error.value, 'max_gap')


@given(name=st.sampled_from(['swivel_limit', 'max_speed']),
       bad=NOT_A_FINITE_NUMBER | at_most(0.0))
def test_steering_map_refuses_a_bad_limit_naming_it(name, bad):
    with pytest.raises(ValueError) as error:
        SteeringMap(P, **{'swivel_limit': 1.0, 'max_speed': 0.5, name: bad})
    assert_refusal_names(error.value, name)


@given(bad=st.tuples(st.sampled_from(['swivel_limit', 'margin']),
                     NOT_A_FINITE_NUMBER | at_most(-1e-9))
       | st.floats(P.max_swivel_angle, 1e3, exclude_min=True).map(
           lambda v: ('swivel_limit', v)))
def test_tip_safe_swivel_limit_refuses_a_bad_argument_naming_it(bad):
    name, value = bad
    with pytest.raises(ValueError) as error:
        tip_safe_swivel_limit(P, **{'swivel_limit': 1.0, 'margin': 0.1, name: value},
                              samples=11)
    assert_refusal_names(error.value, name)


@given(joint=st.sampled_from(NAMES), bad=NON_FINITE)
def test_joint_reader_refuses_a_bad_position_naming_the_joint_and_remembers_nothing(joint,
                                                                                    bad):
    reader = JointReader(NAMES)
    reader.read(1.0, NAMES, [0.0, 1.0, 2.0], [0.0, 1.0, 1.0])
    positions = [0.0, 1.01, 2.01]
    positions[NAMES.index(joint)] = bad
    with pytest.raises(ValueError) as error:
        reader.read(1.01, NAMES, positions, [])
    assert_refusal_names(error.value, joint)
    # The next good message is differenced against the last good one.
    samples = reader.read(1.02, NAMES, [0.0, 1.02, 2.02], [])
    assert samples['rear_left_wheel_joint'].rate == pytest.approx(1.0)
