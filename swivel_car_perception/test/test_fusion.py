"""Fusing detections over frames with odometry, and the pose history it reads; ROS-free."""

import math

import pytest
from swivel_car_perception.core.detector import Detection
from swivel_car_perception.core.fusion import Pose2D, StepTracker
from swivel_car_perception.core.poses import PoseHistory

FRONT_AXLE = 0.433  # [m]


def _seen_from(pose, step_x=2.0, step_yaw=0.2, offset_y=0.1, width=1.0, height=0.08,
               distance_error=0.0, std=0.004):
    """Return the detection of an edge through (step_x, 0) in odom (normal step_yaw) at pose."""
    yaw = step_yaw - pose.yaw
    normal = (math.cos(step_yaw), math.sin(step_yaw))
    rho = step_x * normal[0]
    # base_link's x axis meets the edge at s: n . (p + s h) = rho.
    heading = (math.cos(pose.yaw), math.sin(pose.yaw))
    s = (rho - pose.x * normal[0] - pose.y * normal[1]) / (
        heading[0] * normal[0] + heading[1] * normal[1])
    crossing = (pose.x + s * heading[0], pose.y + s * heading[1])
    along = lambda x, y: -x * normal[1] + y * normal[0]  # noqa: E731
    centre = along(step_x, offset_y) - along(*crossing)
    return Detection(True, '', height, s - FRONT_AXLE + distance_error, yaw, width, centre,
                     0.5, 0.002, std, 0.01, 0.02, True, True)


def test_a_step_seen_while_driving_stays_where_it_is():
    tracker = StepTracker(FRONT_AXLE)
    poses = [Pose2D(0.1 * i, 0.02 * i, 0.05 * i) for i in range(6)]
    errors = [0.006, -0.006, 0.004, -0.004, 0.002, -0.002]  # [m] each frame's distance error
    for pose, error in zip(poses, errors):
        fused = tracker.update(_seen_from(pose, distance_error=error), pose)
    truth = _seen_from(poses[-1])
    assert tracker.frames == 6
    # Six frames of errors averaging zero: the fused distance within their mean's spread.
    assert fused.distance == pytest.approx(truth.distance, abs=0.003)
    assert fused.yaw == pytest.approx(truth.yaw, abs=1e-9)
    # The distance errors move where the x axis meets the edge, and so the offset, by
    # error * tan(yaw): under 2 mm.
    assert fused.offset == pytest.approx(truth.offset, abs=0.002)
    assert fused.width == pytest.approx(1.0) and fused.height == pytest.approx(0.08)
    assert fused.distance_std < 0.004  # six frames of 4 mm, plus 0.6 m of drift at 2 %


def test_a_different_step_starts_a_new_estimate_and_misses_drop_it():
    tracker = StepTracker(FRONT_AXLE, max_misses=2)
    pose = Pose2D(0.0, 0.0, 0.0)
    tracker.update(_seen_from(pose), pose)
    tracker.update(_seen_from(pose), pose)
    moved = tracker.update(_seen_from(pose, step_x=2.5), pose)
    assert tracker.frames == 1 and moved.distance == pytest.approx(2.5 - FRONT_AXLE)
    nothing = Detection(False, 'flat ground: nothing raised ahead')
    for _ in range(3):
        assert tracker.update(nothing, pose) is nothing
    assert tracker.frames == 0


def test_pose_history_interpolates_and_forgets_on_a_reset():
    history = PoseHistory(span=1.0)
    history.add(0, Pose2D(0.0, 0.0, 3.1))
    history.add(100_000_000, Pose2D(1.0, 0.0, -3.1))
    middle = history.at(50_000_000)
    assert middle.x == pytest.approx(0.5) and abs(math.sin(middle.yaw)) < 1e-9
    assert history.at(200_000_000) is None and history.at(-1) is None
    history.add(10, Pose2D(5.0, 0.0, 0.0))  # time went back: a reset
    assert history.at(0) is None and history.at(10).x == 5.0
