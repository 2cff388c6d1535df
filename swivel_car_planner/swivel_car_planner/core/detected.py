"""
climb_step on a detected step: the latest fresh detection, at the car's present pose; ROS-free.

The step detector (swivel_car_perception) publishes each image's step relative to base_link at
the image's stamp. A climb with ``use_detected_step`` takes the latest one if it is at most
``max_age`` old and found a step, moved by odometry from where the car was at its stamp to
where it is now. During the approach each new detection is compared with the edge the climb
works to: one that lies further from it than twice its own one-sigma uncertainty replaces it.
"""

from __future__ import annotations

from dataclasses import replace
import math

from swivel_car_perception.core.detector import Detection
from swivel_car_perception.core.fusion import moved, Pose2D as OdomPose
from swivel_car_perception.core.poses import PoseHistory
from swivel_car_planner.core.geometry import Pose2D, StepEdge, wrap_angle
from swivel_car_planner.core.request import ClimbRequest
from swivel_car_planner.core.state_machine import ClimbStateMachine, Observation
from swivel_car_planner.core.steps import Step

# Nearer than this to the front axle, the front wheels (swung by the swivel while the car
# turns onto its approach) hide parts of the riser: the edge's yaw jumped by 0.05-0.07 rad
# between frames there (detected climb benchmark), so such detections correct nothing.
MIN_FOLLOW_DISTANCE = 0.35  # [m]
# A detection further than this from the edge the climb works to, or of another height, is
# a misreading (odometry drifts by centimetres over an approach), not a better estimate: in
# the detected climb benchmark, 2 cm steps read so during the turn onto the approach moved
# the edge by 0.2-1.1 m and 0.1-0.7 rad and sent the car to its lift point 0.5 rad off.
MAX_SHIFT = 0.1  # [m]
MAX_TURN = 0.1  # [rad]
MAX_HEIGHT_CHANGE = 0.01  # [m]
# Smallest edge move that counts as one, whatever the detection's uncertainty: the odometry's
# own jitter between two frames.
MIN_SHIFT = 0.003  # [m]
MIN_TURN = 0.005  # [rad]


class DetectedSteps:
    """
    The latest detected_step and the car's poses since.

    Parameters
    ----------
    front_axle : float
        The front axle's ground contact along base_link x. # [m]
    max_age : float
        Oldest detection a climb takes. # [s]

    """

    def __init__(self, front_axle: float, max_age: float) -> None:
        self.front_axle = front_axle
        self.max_age = max_age
        self.poses = PoseHistory(span=max(2.0, 2.0 * max_age))
        self._latest: tuple[float, Detection] | None = None  # (stamp [s], detection)
        self._used = -math.inf  # [s] stamp of the last detection that corrected an edge
        self._height = math.nan  # [m] of the step the last request took

    def pose(self, stamp: float, x: float, y: float, yaw: float) -> None:
        """Note where the car is at ``stamp`` [s]: odometry's pose, or a climb's."""
        self.poses.add(round(stamp * 1e9), OdomPose(x, y, yaw))

    def heard(self, stamp: float, detection: Detection) -> None:
        """Note a detection stamped ``stamp`` [s] (relative to base_link then)."""
        if self._latest is None or stamp >= self._latest[0]:
            self._latest = (stamp, detection)

    def fresh(self, now: float) -> tuple[Detection | None, str]:
        """
        Return the latest fresh detection relative to base_link at the newest pose.

        Or None and why there is none, in one line.
        """
        if self._latest is None:
            return None, ('no detected_step heard: is the step detector '
                          '(swivel_car_perception step_detector_node) running, and the depth '
                          'camera on?')
        stamp, detection = self._latest
        age = now - stamp  # [s]
        if age > self.max_age:
            return None, (f'the last detected_step is {age:.2f} s old (detection_max_age '
                          f'{self.max_age} s): is the step detector running?')
        if not detection.found:
            return None, ('the step detector sees no step ahead (flat ground, or the step out '
                          'of view or beyond its range)')
        then, latest = self.poses.at(round(stamp * 1e9)), self.poses.latest
        if then is None or latest is None:
            return None, ("no odometry at the detection's stamp to move it to the car's "
                          'present pose')
        return moved(detection, then, latest[1], self.front_axle), ''

    def request(self, request: ClimbRequest, now: float,
                limit: float = math.inf) -> tuple[ClimbRequest | None, str]:
        """
        Return ``request`` with the fresh detection's step, or None and why (one line).

        The face is the part the camera saw, also where it did not see an end (the face
        reaches at least that far, and the planner keeps every wheel on it). A height above
        the whole car's ``limit`` [m] by no more than twice its one-sigma is the limit's: the
        detection cannot tell that step from one at the limit.
        """
        d, why = self.fresh(now)
        if d is None:
            return None, why
        if limit < d.height <= limit + 2.0 * d.height_std:
            d = replace(d, height=limit)
        self._height = d.height
        return replace(request, step_height=d.height, step_distance=max(0.0, d.distance),
                       step_yaw=d.yaw, step_width=d.width, step_offset=d.offset), ''

    def correction(self, edge: StepEdge, now: float) -> StepEdge | None:
        """
        Return the edge a new fresh detection puts elsewhere than ``edge``, or None.

        Elsewhere: more than twice its one-sigma distance or yaw uncertainty away, but within
        ``MAX_SHIFT`` and ``MAX_TURN`` and of the requested step's height (else a misreading);
        only a detection at least ``MIN_FOLLOW_DISTANCE`` ahead of the front axle counts. The poses
        must be in ``edge``'s frame. The returned edge keeps ``edge``'s point's place along
        the edge (the plan's crossing is measured from it). A detection corrects at most once.
        """
        if self._latest is None:
            return None
        stamp, d = self._latest
        if (not d.found or now - stamp > self.max_age or stamp <= self._used
                or d.distance < MIN_FOLLOW_DISTANCE
                or not abs(d.height - self._height) <= MAX_HEIGHT_CHANGE):
            return None
        then = self.poses.at(round(stamp * 1e9))
        if then is None:
            return None
        self._used = stamp
        seen = StepEdge.from_request(Pose2D(then.x, then.y, then.yaw), self.front_axle,
                                     d.distance, d.yaw)
        shift = edge.signed_distance(seen.px, seen.py)  # [m] along the old normal
        turn = wrap_angle(seen.normal_yaw - edge.normal_yaw)  # [rad]
        if abs(shift) <= max(2.0 * d.distance_std, MIN_SHIFT) \
                and abs(turn) <= max(2.0 * d.yaw_std, MIN_TURN):
            return None
        if abs(shift) > MAX_SHIFT or abs(turn) > MAX_TURN:
            return None
        # The old point dropped onto the new line.
        gap = seen.signed_distance(edge.px, edge.py)
        return StepEdge(edge.px - gap * math.cos(seen.normal_yaw),
                        edge.py - gap * math.sin(seen.normal_yaw), seen.normal_yaw)

    def follow(self, machine: ClimbStateMachine, obs: Observation, stamp: float,
               correct: bool) -> tuple[float, float] | None:
        """
        Note the pose the climb steers by; with ``correct``, follow a new detection.

        The climb's heading is the IMU's (odometry's drifts while the swivel turns at a
        standstill), so the detections are placed with the climb's own poses. In the
        approach proper (the drive to the lift point; not while backing up or repositioning,
        whose paths were planned on the first edge), a new detection beyond its uncertainty
        becomes the climb's edge. Returns
        how far (along the old normal [m]) and by how much (turn [rad]) the edge moved, or
        None.
        """
        climb = machine.climb
        if climb is None:
            return None
        self.pose(stamp, obs.x, obs.y, climb.heading(obs))
        if not correct or machine.step != Step.APPROACH:
            return None
        edge = self.correction(climb.edge, stamp)
        if edge is None:
            return None
        moved_by = (climb.edge.signed_distance(edge.px, edge.py),
                    wrap_angle(edge.normal_yaw - climb.edge.normal_yaw))
        climb.edge = edge
        return moved_by
