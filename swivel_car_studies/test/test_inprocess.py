"""
InProcessStack: fast, deterministic checks of the in-process stack (no ROS, sim time only).

Its identity with the ROS lockstep run, bit for bit per control period, is checked by
tests/test_inprocess_identity.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from swivel_car_model.description import CarDescription
from swivel_car_planner.core import ClimbRequest, ErrorCode
from swivel_car_studies.inprocess import InProcessStack, StackConfig


@pytest.fixture
def stack():
    with InProcessStack() as running:
        yield running


def test_configuration_is_the_installed_one_with_overrides():
    config = StackConfig.installed(robot={'body_mass': 5.0}, planner={'climb_speed': 2.5})
    assert config.robot == CarDescription(body_mass=5.0)
    assert config.sim.physics.description == config.robot
    assert config.controller.max_torque == config.robot.swivel_torque_limit
    assert config.planner.climb_speed == 2.5
    assert config.sim.control_period == 0.01 and config.sim.steps_per_period == 5
    assert StackConfig.installed('car_like').steer_joint == 'steering_joint'
    with pytest.raises(ValueError, match='climb_sped'):
        StackConfig.installed(planner={'climb_sped': 2.5})
    with pytest.raises(ValueError, match='robot_variant'):
        StackConfig.installed('tank')


def test_a_short_drive_moves_forward_and_records_every_period(stack):
    stack.drive(0.3, 0.0, 1.0)
    truth = stack.ground_truth()
    assert 0.15 < truth.x < 0.35 and abs(truth.y) < 0.01, truth
    assert stack.time == pytest.approx(1.0)
    trajectory = stack.trajectory()
    assert len(trajectory) == 100
    assert np.all(np.diff(trajectory.time) > 0.0)
    assert trajectory.drive_speed[-1] == pytest.approx(0.3 / stack.config.robot.r)
    # The cmd_vel deadman stops the car once drive() no longer renews the command.
    stack.settle(1.5)
    assert stack.ground_truth().speed < 0.01


def test_reset_odometry_moves_the_odometry_to_the_origin_not_the_car(stack):
    stack.drive(0.3, 0.0, 0.5)
    before = stack.ground_truth()
    stack.reset_odometry()
    odometry = stack.odometry.odometry
    assert (odometry.x, odometry.y, odometry.yaw, odometry.v) == (0.0, 0.0, 0.0, 0.0)
    assert stack.ground_truth() == before
    stack.drive(0.3, 0.0, 0.5)
    assert odometry.x == pytest.approx(stack.ground_truth().x - before.x, abs=0.01)


def test_the_same_calls_give_the_same_floats():
    runs = []
    for _ in range(2):
        with InProcessStack() as stack:
            stack.drive(0.2, 0.3, 0.5)
            runs.append(stack.trajectory())
    assert np.array_equal(runs[0].position, runs[1].position)
    assert np.array_equal(runs[0].joint_positions, runs[1].joint_positions)


def test_a_refused_request_does_not_move_the_car(stack):
    result = stack.climb(ClimbRequest(0.5, 1.0, 0.0))
    assert not result.success
    assert result.error_code == ErrorCode.UNREACHABLE_HEIGHT, result.message
    assert result.outcome is None and len(result.trajectory) == 0
    assert stack.time == 0.0
    invalid = stack.climb(ClimbRequest(-0.01, 1.0, 0.0))
    assert invalid.error_code == ErrorCode.INVALID_REQUEST and 'step_height' in invalid.message


def test_a_3cm_step_is_climbed_with_all_four_wheels_on_top(stack):
    height, distance = 0.03, 1.0
    stack.spawn_step(height, distance)
    result = stack.climb(ClimbRequest(height, distance, 0.0))
    assert result.success, result.message
    assert result.error_code == ErrorCode.NONE
    assert stack.four_wheels_on_top(height) and stack.front_on_top(height)
    assert result.start_time == 0.0
    assert len(result.trajectory) == round(result.outcome.duration / stack.control_period) + 1
    assert result.outcome.distance_travelled > distance
    assert math.isclose(np.max(np.abs(result.trajectory.swivel_torque)),
                        result.outcome.peak_torque)
