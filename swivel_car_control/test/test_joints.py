"""Unit tests of reading named joints from JointState-like data."""

import math

import pytest

from swivel_car_control.joints import JointReader, MissingJointError

NAMES = ['swivel_joint', 'rear_left_wheel_joint', 'rear_right_wheel_joint']


def test_reads_by_name_whatever_the_order_of_the_message():
    reader = JointReader(['swivel_joint', 'rear_right_wheel_joint'])
    first = reader.read(0.0, NAMES, [0.1, 1.0, 2.0], [0.5, 3.0, 4.0])
    assert (first['swivel_joint'].position, first['swivel_joint'].rate) == (0.1, 0.5)
    assert first['rear_right_wheel_joint'].rate == 4.0
    # Another layout in the next message (a driver that reorders, or another publisher).
    second = reader.read(0.01, NAMES[::-1], [2.5, 1.5, 0.2], [4.5, 3.5, 0.6])
    assert (second['swivel_joint'].position, second['swivel_joint'].rate) == (0.2, 0.6)
    assert second['rear_right_wheel_joint'].position == 2.5


def test_a_missing_velocity_is_differenced_across_the_wrap():
    reader = JointReader(['rear_left_wheel_joint'])
    with pytest.raises(MissingJointError, match='no velocity'):
        reader.read(0.0, NAMES, [0.0, math.pi - 0.01, 0.0], [])
    sample = reader.read(0.01, NAMES, [0.0, -math.pi + 0.01, 0.0], [0.0, math.nan, 0.0])
    assert sample['rear_left_wheel_joint'].rate == pytest.approx(2.0)


def test_a_joint_that_leaves_the_message_is_missing_and_nothing_is_remembered():
    reader = JointReader(['swivel_joint', 'rear_left_wheel_joint'])
    reader.read(0.0, NAMES, [0.1, 1.0, 2.0], [0.0, 0.0, 0.0])
    with pytest.raises(MissingJointError, match='rear_left_wheel_joint'):
        reader.read(0.01, ['swivel_joint', 'rear_right_wheel_joint'], [0.3, 2.0], [0.0, 0.0])
    with pytest.raises(MissingJointError, match='swivel_joint'):
        reader.read(0.02, NAMES, [math.nan, 1.0, 2.0], [0.0, 0.0, 0.0])
    # The last good message is still the one to difference against.
    sample = reader.read(0.1, NAMES, [0.2, 1.0, 2.0], [])
    assert sample['swivel_joint'].rate == pytest.approx(1.0)
