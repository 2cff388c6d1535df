"""
The planner core's configuration and request checks, as properties (issue 12).

A bad configuration value is refused with one ValueError naming the field; a bad climb
request is answered INVALID_REQUEST naming the field, before any model call; good ones pass.
"""

from dataclasses import fields

from bad_values import assert_refusal_names, at_most, NOT_A_FINITE_NUMBER
from hypothesis import given, strategies as st
import pytest
from swivel_car_planner.core.codes import ErrorCode
from swivel_car_planner.core.config import PlannerConfig
from swivel_car_planner.core.request import ClimbRequest, validate_request

CONFIG = PlannerConfig()
CONFIG_FIELDS = [item.name for item in fields(PlannerConfig)]
REQUEST_NUMBERS = ('step_height', 'step_distance', 'step_yaw', 'time_allowance', 'step_width',
                   'step_offset')
GOOD = {'step_height': 0.04, 'step_distance': 1.0, 'step_yaw': 0.0}


@given(name=st.sampled_from(CONFIG_FIELDS), bad=NOT_A_FINITE_NUMBER | at_most(-1e-9))
def test_config_refuses_a_bad_field_naming_it(name, bad):
    with pytest.raises(ValueError) as error:
        PlannerConfig(**{name: bad})
    assert_refusal_names(error.value, name)


@given(name=st.sampled_from(['max_step_yaw', 'max_lead_angle', 'push_lead']),
       bad=st.floats(1.5708, 1e6))
def test_config_refuses_an_angle_of_a_right_angle_or_more(name, bad):
    with pytest.raises(ValueError) as error:
        PlannerConfig(**{name: bad})
    assert_refusal_names(error.value, name)


@given(name=st.sampled_from(REQUEST_NUMBERS), bad=NOT_A_FINITE_NUMBER)
def test_a_request_field_that_is_not_a_finite_number_is_invalid_naming_it(name, bad):
    code, message = validate_request(ClimbRequest(**{**GOOD, name: bad}), CONFIG)
    assert code == ErrorCode.INVALID_REQUEST
    assert_refusal_names(ValueError(message), name)


@given(st.one_of(
    at_most(0.0).map(lambda v: ('step_height', v)),
    at_most(-1e-9).map(lambda v: ('step_distance', v)),
    st.floats(CONFIG.max_step_distance, 1e9, exclude_min=True).map(
        lambda v: ('step_distance', v)),
    st.floats(CONFIG.max_step_yaw, 1e9, exclude_min=True).flatmap(
        lambda v: st.sampled_from([('step_yaw', v), ('step_yaw', -v)])),
    at_most(-1e-9).map(lambda v: ('step_width', v)),
    st.floats(CONFIG.max_step_distance, 1e9, exclude_min=True).map(
        lambda v: ('step_offset', v)),
    at_most(-1e-9).map(lambda v: ('time_allowance', v))))
def test_a_request_field_out_of_range_is_invalid_naming_it(bad):
    name, value = bad
    code, message = validate_request(ClimbRequest(**{**GOOD, name: value}), CONFIG)
    assert code == ErrorCode.INVALID_REQUEST
    assert_refusal_names(ValueError(message), name)


@given(height=st.floats(1e-6, 10.0), distance=st.floats(0.0, CONFIG.max_step_distance),
       yaw=st.floats(-CONFIG.max_step_yaw, CONFIG.max_step_yaw), width=st.floats(0.0, 100.0),
       offset=st.floats(-CONFIG.max_step_distance, CONFIG.max_step_distance),
       allowance=st.floats(0.0, 1e4))
def test_a_well_formed_request_passes(height, distance, yaw, width, offset, allowance):
    assert validate_request(ClimbRequest(
        step_height=height, step_distance=distance, step_yaw=yaw, step_width=width,
        step_offset=offset, time_allowance=allowance), CONFIG) == (ErrorCode.NONE, '')
