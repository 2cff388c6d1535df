"""The detector and the fusion together, as step_detector_node runs them; ROS-free."""

from __future__ import annotations

import numpy as np

from swivel_car_perception.core.detector import Detection, StepDetector
from swivel_car_perception.core.fusion import Pose2D, StepTracker
from swivel_car_perception.core.poses import PoseHistory


class StepPerception:
    """
    Depth frames and odometry poses in, the fused nearest step out.

    Parameters
    ----------
    detector : StepDetector or None
        None until the camera's intrinsics are known; set it before ``frame``.
    tracker : StepTracker

    """

    def __init__(self, detector: StepDetector | None, tracker: StepTracker) -> None:
        self.detector = detector
        self.tracker = tracker
        self.poses = PoseHistory()

    def odom(self, stamp: int, pose: Pose2D) -> None:
        """Note odometry's ``pose`` at ``stamp`` [ns]; a stamp gone back starts afresh."""
        latest = self.poses.latest
        if latest is not None and stamp < latest[0]:
            self.tracker.reset()
        self.poses.add(stamp, pose)

    def frame(self, depth: np.ndarray, stamp: int) -> tuple[Detection, bool]:
        """
        Detect in ``depth`` [m] taken at ``stamp`` [ns]; fuse with the frames before.

        Returns the detection (relative to base_link at ``stamp``) and whether it was fused
        (False: no odometry at that stamp, the frame's own detection).

        Raises
        ------
        ValueError
            ``depth`` is not of the detector's image size.

        """
        detection = self.detector.detect(depth)
        pose = self.poses.at(stamp)
        if pose is None:
            return detection, False
        return self.tracker.update(detection, pose), True
