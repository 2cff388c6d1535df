"""
A kinematic stand-in for the robot on flat ground, for tests of the climb logic.

The model's planar kinematics (``planar.OffsetTricycleOdometry``) integrate the commanded
swivel and drive; the swivel follows the rate-limited set point, exactly or ``sag`` short of
it (as a PID under load), or not at all (``stuck``); pitch is the model's lift angle, plus,
with a step placed (``place_step``), the pitch of the front axle on it while the rear axle is
still below. No contact and no physics: the sim is for those.
"""

from __future__ import annotations

import math

from swivel_car_model import kinematics, planar
from swivel_car_model.params import SwivelCarParams

from swivel_car_planner.core import Command, Observation
from swivel_car_planner.core.geometry import Pose2D, StepEdge

DT = 0.01  # [s] control period
DEFAULT_SWIVEL_RATE = 1.5  # [rad/s] the controller's, for commands with max_rate 0


class KinematicCar:
    """Flat-ground car: swivel follows the rate-limited set point unless ``stuck``."""

    def __init__(self, p: SwivelCarParams = SwivelCarParams(), yaw: float = 0.0) -> None:
        self.p = p
        self.odometry = planar.OffsetTricycleOdometry(p)
        self.odometry.set_pose(0.0, 0.0, yaw)
        self.cycles = 0  # control periods so far; time is cycles * DT, exact in ns
        self.swivel = 0.0  # [rad]
        self.rate = 0.0  # [rad/s]
        self.set_point = 0.0  # [rad]
        self.stuck = False
        self.blocked = False
        self.extra_pitch = 0.0  # [rad] added nose-down pitch
        self.roll = 0.0  # [rad] as the IMU reports it
        self.extra_yaw = 0.0  # [rad] added to the IMU heading (a slip odometry cannot see)
        self.sag = 0.0  # [rad] how far short of its set point the loaded swivel settles
        self.speed = 0.0  # [m/s] forward, as the drive makes it (no inertia)
        self.commands: list[Command] = []
        self.step: StepEdge | None = None
        self.step_pitch = 0.0  # [rad] nose up, the front axle on the step and the rear below

    def place_step(self, height: float, distance: float, yaw: float = 0.0) -> None:
        """Place a step where a climb request names it from the car's pose now [m], [rad]."""
        pose = Pose2D(self.odometry.x, self.odometry.y, self.odometry.yaw)
        self.step = StepEdge.from_request(pose, self.p.wheelbase, distance, yaw)
        self.step_pitch = math.asin(min(1.0, height / self.p.wheelbase))

    def _on_step_pitch(self) -> float:
        if self.step is None:
            return 0.0
        pose = Pose2D(self.odometry.x, self.odometry.y, self.odometry.yaw)
        front = self.step.signed_distance(*pose.transform(self.p.wheelbase, 0.0))
        rear = self.step.signed_distance(*pose.transform(0.0, 0.0))
        return -self.step_pitch if front > 0.0 > rear else 0.0

    def observe(self) -> Observation:
        """Return the car's state; the swivel torque is a stand-in, 10 N m/rad of swivel angle."""
        return Observation(
            time=self.time, x=self.odometry.x, y=self.odometry.y, yaw=self.odometry.yaw,
            swivel=self.swivel, swivel_rate=self.rate, set_point=self.set_point,
            torque=10.0 * self.swivel,
            pitch=(-float(kinematics.lift_angle(self.p, self.swivel)) + self.extra_pitch
                   + self._on_step_pitch()),
            roll=self.roll, imu_yaw=self.odometry.yaw + self.extra_yaw, speed=self.speed)

    def apply(self, command: Command) -> None:
        """Follow ``command`` for one control period."""
        self.commands.append(command)
        rate = command.max_rate if command.max_rate > 0.0 else DEFAULT_SWIVEL_RATE
        step = max(-rate * DT, min(rate * DT, command.angle - self.set_point))
        self.set_point += step
        loaded = self.set_point - math.copysign(min(self.sag, abs(self.set_point)),
                                                self.set_point)
        new = self.swivel if self.stuck else loaded
        self.rate = (new - self.swivel) / DT
        self.swivel = new
        wheel = 0.0 if self.blocked else command.drive_speed
        self.odometry.update(self.swivel, self.rate, wheel, DT)
        self.speed = self.odometry.v
        self.cycles += 1

    @property
    def time(self) -> float:
        return self.cycles * DT  # [s]
