"""robot_frames' ROS-free parts: the rate limit of /tf and the frames of fixed joints."""

import math

import pytest
from swivel_car_telemetry.robot_frames import fixed_frames, moving_frames, parse_joints, RateLimit

URDF = """<robot name="r">
  <link name="base_link"/><link name="wheel"/><link name="camera_link"/>
  <joint name="wheel_joint" type="continuous"><parent link="base_link"/><child link="wheel"/>
    <origin xyz="0 0.15 0"/><axis xyz="0 1 0"/></joint>
  <joint name="camera_joint" type="fixed"><parent link="base_link"/><child link="camera_link"/>
    <origin xyz="0.3 0 0.2" rpy="0 0.5 0"/></joint>
</robot>"""


def test_the_rate_limit_passes_one_message_per_period_of_message_time():
    limit = RateLimit(0.05)
    stamps = [1.0 + 0.01 * k for k in range(21)]  # [s] a 100 Hz joint_states
    assert [t for t in stamps if limit.due(t)] == pytest.approx([1.0, 1.05, 1.1, 1.15, 1.2])


def test_the_rate_limit_starts_again_when_time_goes_back():
    limit = RateLimit(0.05)
    assert [limit.due(t) for t in (5.0, 5.01, 0.0, 0.01, 0.05)] == [
        True, False, True, False, True]


@pytest.mark.parametrize('period', [-0.1, math.nan, math.inf, '0.1'])
def test_a_bad_period_is_refused(period):
    with pytest.raises(ValueError, match='period'):
        RateLimit(period)


def test_fixed_joints_are_static_frames_and_moving_ones_follow_their_position():
    joints = parse_joints(URDF)
    (camera,) = fixed_frames(joints)
    assert (camera.parent, camera.child, camera.translation) == ('base_link', 'camera_link',
                                                                 (0.3, 0.0, 0.2))
    assert camera.rotation == pytest.approx((0.0, math.sin(0.25), 0.0, math.cos(0.25)))
    (wheel,) = moving_frames(joints, {'wheel_joint': 1.0, 'other_joint': 2.0})
    assert wheel.child == 'wheel'
    assert wheel.rotation == pytest.approx((0.0, math.sin(0.5), 0.0, math.cos(0.5)))
    assert moving_frames(joints, {}) == []
