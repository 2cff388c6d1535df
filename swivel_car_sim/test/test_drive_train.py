"""The drive train's torques on their own, without pybullet."""

import dataclasses

import pytest
from swivel_car_model.description import CarDescription

from swivel_car_sim.drive_train import DriveTrain

DT = 0.002  # [s]


def test_the_speed_integral_is_frozen_while_the_motor_saturates():
    description = CarDescription()
    train = DriveTrain(description, DT)
    still = (0.0, 0.0)  # (position [rad], velocity [rad/s])
    for _ in range(100):
        efforts = train.efforts(still, still, still, still, 0.0, 20.0, False)
    assert efforts[1] + efforts[2] == pytest.approx(description.drive_torque_limit)
    at_speed = (0.0, 20.0)
    # No error and no wind-up: no torque.
    assert train.efforts(at_speed, at_speed, at_speed, at_speed, 0.0, 20.0, False) == [0.0] * 5


def test_a_tripped_watchdog_zeroes_the_swivel_and_brakes_the_drive():
    train = DriveTrain(CarDescription(), DT)
    rolling = (0.0, 5.0)
    efforts = train.efforts(rolling, rolling, rolling, rolling, 3.0, 5.0, True)
    assert efforts[0] == 0.0
    assert all(torque < 0.0 for torque in efforts[1:3])


def test_a_locked_axle_moves_torque_to_the_lagging_wheel_an_open_one_splits_it():
    wheels = ((0.0, 1.0), (0.1, 1.0), (0.0, 1.0), (0.0, 1.0))  # rear left lags 0.1 rad

    def rear_torques(differential):
        description = dataclasses.replace(CarDescription(), rear_differential=differential)
        return DriveTrain(description, DT).efforts(*wheels, 0.0, 2.0, False)[1:3]
    open_left, open_right = rear_torques('open')
    locked_left, locked_right = rear_torques('locked')
    assert open_left == open_right
    assert locked_left + locked_right == pytest.approx(open_left + open_right)
    assert locked_left > locked_right
