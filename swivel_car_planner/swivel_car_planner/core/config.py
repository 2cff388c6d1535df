"""The planner's tuning, one validated frozen dataclass (filled from ROS parameters)."""

from __future__ import annotations

from dataclasses import dataclass, fields
import math
from typing import ClassVar

from swivel_car_model.checks import check_finite_number
from swivel_car_model.description import described


@dataclass(frozen=True)
class PlannerConfig:
    """
    Margins, limits, speeds and monitor thresholds of the climb.

    Each field's metadata ``description`` (with its unit) is also its ROS parameter's.

    Raises
    ------
    ValueError
        A field is not finite or out of its range; the message names the field.

    """

    tip_over_margin: float = described(
        0.15, 'margin the plan keeps on the tip-over rule (pi - phi)/2 - theta1 [rad]')
    clearance_margin: float = described(
        0.01, 'lifted wheel lowest point above the step top [m]')
    max_step_distance: float = described(3.0, 'farthest step edge a request may name [m]')
    max_step_yaw: float = described(1.0, 'largest |step_yaw| the planner accepts [rad]')
    max_backup: float = described(
        1.0, 'a step too close to turn onto the approach: the car first backs up straight, '
        'at most this far (what is behind it is not checked); 0: refuse instead [m]')
    max_reposition: float = described(
        4.0, 'where backing up does not make room for the approach either, the car first '
        'drives to a pose it can start from (turning with the swivel at swivel_limit, '
        'straight, forwards or backwards, clear of the step): on a path at most this long; '
        '0: refuse instead [m]')
    reposition_clearance: float = described(
        0.1, "repositioning keeps the car's footprint this far from the step's box (the "
        "swivel's moves at a standstill and odometry drift move it off the planned path) [m]")
    lead_margin: float = described(
        0.03, 'lifted wheel past the edge while the other front wheel is still clear [m]')
    lift_gap: float = described(0.03, 'lifted wheel front to the riser when the lift starts [m]')
    max_lead_angle: float = described(0.8, 'largest approach angle to the step normal [rad]')
    push_lift_height: float = described(
        0.24, 'steps at least this high use the push-lift; lower ones too where no '
        'approach heading lets the lifted wheel lead (WHEEL_INTERFERENCE) [m]')
    push_lead: float = described(
        0.6, 'push-lift (steps no standard approach can lift onto, WHEEL_INTERFERENCE): '
        'heading to the step normal at the lift, turned so the grounded front wheel leads '
        '[rad]')
    push_gap: float = described(
        0.03, "push-lift: the grounded front wheel's front to the riser when the lift starts "
        '[m]')
    push_margin: float = described(
        0.05, 'push-lift: the advance ends with the point where the lifted wheel will land '
        'this far past the edge [m]')
    set_down_speed: float = described(
        1.0, 'push-lift: drive speed at the wheels while the swivel sets the lifted wheel '
        'down (the rear axle follows the front as it pitches up) [rad/s]')
    approach_speed: float = described(3.0, 'drive speed at the wheels while approaching [rad/s]')
    climb_speed: float = described(2.0, 'drive speed at the wheels while climbing [rad/s]')
    rear_speed: float = described(
        6.5, 'drive speed at the wheels while the rear axle climbs; its momentum helps the '
        'rear wheels up the riser [rad/s]')
    swivel_rate: float = described(0.6, 'swivel rate limit for lift and set-down [rad/s]')
    max_steer: float = described(0.35, 'largest steering angle used to align [rad]')
    heading_gain: float = described(1.5, 'steering angle per heading error [1]')
    align_tolerance: float = described(0.12, 'heading error allowed when the lift starts [rad]')
    swivel_tolerance: float = described(0.04, 'swivel counts as at its target within this [rad]')
    settle_rate: float = described(0.05, 'swivel counts as at rest below this rate [rad/s]')
    settle_time: float = described(0.3, 'swivel at its target and at rest this long [s]')
    stop_speed: float = described(
        0.02, 'a climb asked while the car is faster than this first stops it, the swivel '
              'held [m/s]')
    rear_slip_allowance: float = described(
        0.25, 'odometry past the edge beyond rest_margin with the car still pitched: the '
        'rear axle failed to climb [m]')
    edge_margin: float = described(
        0.05, "every wheel on top stays this far inside the sides of the step's top face "
        '(when the request gives its width) [m]')
    crossing_gain: float = described(
        4.0, 'approach: heading correction per metre of the centre line off its planned '
        'crossing of the edge [rad/m]')
    rest_margin: float = described(
        0.05, 'rear wheel contacts past the edge to call the climb done [m]')
    stop_allowance: float = described(
        0.3, 'travel on the top face after the rear wheels are rest_margin past the edge: '
        'they leave the riser at speed, the car comes level, then stops [m]')
    level_tolerance: float = described(
        0.12, 'largest |pitch| that counts as level while the rear axle climbs [rad]')
    rest_tolerance: float = described(
        0.05, 'largest |pitch| (and twice that |roll|) of the car standing on top to call '
        'the climb done [rad]')
    bias_gain: float = described(
        2.0, 'outer loop: command bias per remaining swivel error and second [1/s]')
    max_bias: float = described(0.6, 'outer loop: largest command bias [rad]')
    stall_progress: float = described(
        0.01, 'the swivel must close on its goal by this much every stall_time [rad]')
    stall_time: float = described(4.0, 'swivel making no headway this long: stall [s]')
    slip_yaw_tolerance: float = described(
        0.6, 'IMU and odometry headings parting this far while the rear axle climbs: the '
        'wheels slip (locked differentials scrub: on climbs that ended on top in the sim '
        'they parted by more than 0.25 rad) [rad]')
    no_progress_time: float = described(4.0, 'window of the no-progress monitor [s]')
    min_progress: float = described(0.01, 'path length the car must make in that window [m]')
    attitude_time_constant: float = described(
        10.0, "roll and pitch: the gyro's integral, pulled towards the IMU's fused angles with "
        'this time constant (bandwidth 1/(2 pi it)): the fused angles take a jolt for a tilt '
        '(core.inputs.Attitude) [s]')
    pitch_abort_margin: float = described(
        0.08, 'abort when the nose-up pitch comes this near the tip-over rule [rad]')
    time_allowance: float = described(60.0, 'default climb time limit, sim time [s]')
    # Every field: each climb reads them from its start, so all may change while the node runs.
    LIVE: ClassVar[tuple[str, ...]]

    def __post_init__(self) -> None:
        for item in fields(self):
            value = getattr(self, item.name)
            check_finite_number(item.name, value)
            if value < 0.0:
                raise ValueError(f'{item.name} must be >= 0, got {value!r}')
        for name in ('max_step_distance', 'max_step_yaw', 'max_lead_angle', 'push_lead',
                     'approach_speed', 'climb_speed', 'rear_speed', 'set_down_speed',
                     'swivel_rate', 'max_steer',
                     'swivel_tolerance', 'settle_rate', 'stop_speed',
                     'stall_progress',
                     'stall_time', 'slip_yaw_tolerance', 'no_progress_time', 'min_progress',
                     'attitude_time_constant',
                     'time_allowance'):
            if getattr(self, name) <= 0.0:
                raise ValueError(f'{name} must be > 0, got {getattr(self, name)!r}')
        for name in ('max_step_yaw', 'max_lead_angle', 'push_lead'):
            if getattr(self, name) >= math.pi / 2:
                raise ValueError(f'{name} must be below pi/2, got {getattr(self, name)!r}')


PlannerConfig.LIVE = tuple(item.name for item in fields(PlannerConfig))
