"""Unit tests of the planner core's request validation, config and edge geometry."""

import math

from hypothesis import given, strategies as st
import pytest

from swivel_car_planner.core import ClimbRequest, ErrorCode, PlannerConfig, validate_request
from swivel_car_planner.core.geometry import Pose2D, StepEdge, wrap_angle

CONFIG = PlannerConfig()
GOOD = {'step_height': 0.05, 'step_distance': 1.0, 'step_yaw': 0.1}


def test_default_config_is_valid():
    assert CONFIG.swivel_rate > 0.0


@pytest.mark.parametrize('name, value', [
    ('climb_speed', math.nan), ('clearance_margin', -0.01), ('swivel_rate', 0.0),
    ('max_step_yaw', math.pi / 2), ('time_allowance', math.inf), ('stall_time', True),
    ('stop_speed', 0.0), ('stop_speed', math.nan), ('max_backup', -0.1),
    ('max_backup', math.inf), ('stop_allowance', -0.1), ('rest_tolerance', math.nan),
    ('push_lift_height', -0.01), ('push_lead', 0.0), ('push_lead', math.pi / 2),
    ('push_gap', math.nan), ('push_margin', -0.05), ('set_down_speed', 0.0)])
def test_bad_config_names_the_field(name, value):
    with pytest.raises(ValueError, match=name):
        PlannerConfig(**{name: value})


def test_well_formed_request_passes():
    assert validate_request(ClimbRequest(**GOOD), CONFIG) == (ErrorCode.NONE, '')


@pytest.mark.parametrize('name, value', [
    ('step_height', math.nan), ('step_height', 0.0), ('step_height', -0.02),
    ('step_height', math.inf), ('step_distance', -0.1), ('step_distance', math.nan),
    ('step_distance', CONFIG.max_step_distance + 0.1), ('step_yaw', math.inf),
    ('step_yaw', CONFIG.max_step_yaw + 0.01), ('step_yaw', -math.pi / 2),
    ('time_allowance', -1.0), ('time_allowance', math.nan)])
def test_bad_request_is_invalid_and_names_the_field(name, value):
    code, message = validate_request(ClimbRequest(**{**GOOD, name: value}), CONFIG)
    assert code == ErrorCode.INVALID_REQUEST
    assert name in message


def test_edge_ahead_of_a_car_at_the_origin():
    edge = StepEdge.from_request(Pose2D(0.0, 0.0, 0.0), 0.4, 1.0, 0.0)
    assert edge.signed_distance(0.4, 0.0) == pytest.approx(-1.0)
    assert edge.signed_distance(1.5, 3.0) == pytest.approx(0.1)
    assert edge.relative_heading(0.0) == pytest.approx(0.0)


def test_yawed_edge_puts_the_left_wheel_nearer_for_positive_yaw():
    # Edge turned counter-clockwise from the y axis: its left end comes towards the car.
    edge = StepEdge.from_request(Pose2D(0.0, 0.0, 0.0), 0.4, 1.0, 0.3)
    assert edge.signed_distance(0.4, 0.15) > edge.signed_distance(0.4, -0.15)
    assert edge.relative_heading(0.0) == pytest.approx(-0.3)


finite = st.floats(-10.0, 10.0)


@given(finite, finite, st.floats(-3.0, 3.0), st.floats(0.0, 3.0), st.floats(-1.0, 1.0),
       st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
def test_edge_distances_do_not_depend_on_where_the_car_starts(x, y, yaw, distance, step_yaw,
                                                              bx, by):
    here = StepEdge.from_request(Pose2D(x, y, yaw), 0.4, distance, step_yaw)
    origin = StepEdge.from_request(Pose2D(0.0, 0.0, 0.0), 0.4, distance, step_yaw)
    assert here.signed_distance(*Pose2D(x, y, yaw).transform(bx, by)) == pytest.approx(
        origin.signed_distance(bx, by), abs=1e-9)
    assert here.relative_heading(yaw) == pytest.approx(origin.relative_heading(0.0), abs=1e-9)


@given(st.floats(-50.0, 50.0))
def test_wrap_angle_stays_in_range_and_keeps_the_direction(angle):
    wrapped = wrap_angle(angle)
    assert -math.pi <= wrapped < math.pi
    assert math.cos(wrapped) == pytest.approx(math.cos(angle), abs=1e-9)
    assert math.sin(wrapped) == pytest.approx(math.sin(angle), abs=1e-9)
