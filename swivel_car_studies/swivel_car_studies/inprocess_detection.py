"""
The depth camera, the step detector and a detected climb's step, for the in-process stack.

What sim_node's camera, step_detector_node and planner_node's ``use_detected_step`` do,
without ROS: each camera period a frame of the sim's camera, the detector and the fusion with
the odometry's poses, the planner's latest detection. Nothing here imports rclpy.
"""

from __future__ import annotations

from swivel_car_model.description import CarDescription
from swivel_car_perception.core.detector import Intrinsics, Mount, StepDetector
from swivel_car_perception.core.fusion import Pose2D, StepTracker
from swivel_car_perception.core.perception import StepPerception
from swivel_car_planner.core.detected import DetectedSteps
from swivel_car_sim.depth_camera import CameraConfig, DepthCamera, PARAMETERS
from swivel_car_sim.physics import SwivelCarSim
from swivel_car_sim.sensor_models import StereoDepthNoise

# The nodes' defaults: sim_node's camera, the planner's detection_max_age.
CAMERA = CameraConfig.from_values({name: default for name, (default, _) in PARAMETERS.items()},
                                  0.01)
DETECTION_MAX_AGE = 0.5  # [s]


class InProcessDetection:
    """
    The camera on the sim's car, the detector on its frames, the planner's detected step.

    Parameters
    ----------
    sim : SwivelCarSim
    description : CarDescription
    control_period : float  # [s]
    seed : int
        The camera noise's seed.

    """

    def __init__(self, sim: SwivelCarSim, description: CarDescription, control_period: float,
                 seed: int = 0) -> None:
        self.camera = DepthCamera(sim.client, description, CAMERA.width, CAMERA.height,
                                  StereoDepthNoise(), seed)
        k = self.camera.intrinsics
        self.perception = StepPerception(
            StepDetector(Intrinsics(k.width, k.height, k.fx, k.fy, k.cx, k.cy),
                         Mount.of(description)),
            StepTracker(description.wheelbase))
        self.planner = DetectedSteps(description.wheelbase, DETECTION_MAX_AGE)
        self._every = CAMERA.periods_per_frame(control_period)
        self.frames = 0

    def period(self, periods: int, time: float, state, odom: Pose2D | None,
               climbing: bool) -> None:
        """
        One control period at ``time`` [s]: odometry's pose, a frame when one is due.

        ``state`` is the sim's RobotState at ``time``; ``climbing``: the running climb notes
        the planner's poses itself (``DetectedSteps.follow``).
        """
        stamp = round(time * 1e9)  # [ns]
        if odom is not None:
            self.perception.odom(stamp, odom)
            if not climbing:
                self.planner.pose(time, odom.x, odom.y, odom.yaw)
        if periods % self._every:
            return
        depth = self.camera.capture(state.position, state.orientation, stamp)
        detection, _ = self.perception.frame(depth, stamp)
        self.planner.heard(time, detection)
        self.frames += 1
