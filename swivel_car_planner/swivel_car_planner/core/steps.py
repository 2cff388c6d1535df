"""
The climb's steps: one class each, built when the climb enters the step, asked once a cycle.

A step's ``update`` returns the command to send, the ``Step`` to enter now (entered in the
same cycle), or a ``Finish``. A step keeps only its own state; what the steps share is the
``Climb``: the request's edge, the geometry of the car on it and the swivel's outer loop.
``BEHAVIOURS`` says which class runs which step: a ``Step`` without one raises on entry.

Every step but APPROACH wants the *measured* swivel at an angle. Under load (a wheel lifted,
or the front of the car lifted with one wheel on the step) the controller's PID settles short
of its set point (measured in the sim: up to 0.3 rad with the thesis gains and an integral
that only acts within 0.1 rad of the set point). So the planner closes an outer loop
(``Climb.hold``): it commands the wanted angle plus a bias that integrates the remaining error
(``bias_gain``, at most ``max_bias``) once the controller's set point has caught up with the
command, the way an operator would push the stick further. The bias carries from step to step
while they want the same angle.

The heading always comes from the IMU, the position from odometry: the wheels skid when the
swivel turns at a standstill, and odometry's heading then drifts (up to 0.3 rad in the sim).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
import math
from typing import Callable

from swivel_car_model import dynamics, kinematics
from swivel_car_model.params import SwivelCarParams

from swivel_car_planner.core.codes import ErrorCode, Phase
from swivel_car_planner.core.config import PlannerConfig
from swivel_car_planner.core.geometry import Pose2D, StepEdge, wrap_angle
from swivel_car_planner.core.plan import ClimbPlan, PROCEDURE_SEMI_ACTIVE, semi_active_turn
from swivel_car_planner.core.reposition import path_curvature, reposition_length, Segment


class Step(Enum):
    """The steps of the climb, in order: (action phase, share of the progress at its start)."""

    STOP = (Phase.APPROACH, 0.0)
    BACK_UP = (Phase.APPROACH, 0.02)
    REPOSITION = (Phase.APPROACH, 0.03)
    APPROACH = (Phase.APPROACH, 0.05)
    PRESS = (Phase.APPROACH, 0.15)
    LIFT = (Phase.LIFT, 0.2)
    ADVANCE = (Phase.ADVANCE, 0.3)
    SET_DOWN = (Phase.SET_DOWN, 0.4)
    SECOND_ADVANCE = (Phase.CLIMB_REST, 0.5)
    SECOND_SET_DOWN = (Phase.CLIMB_REST, 0.6)
    REAR = (Phase.CLIMB_REST, 0.65)
    STOP_ON_TOP = (Phase.CLIMB_REST, 0.95)
    DONE = (Phase.DONE, 1.0)

    @property
    def phase(self) -> Phase:
        return self.value[0]

    @property
    def progress_start(self) -> float:
        return self.value[1]


# [m] how far odometry puts the rear wheels behind where they are while they climb
# (measured up to 0.09 m)
_REAR_ODOMETRY_LAG = 0.1


@dataclass(frozen=True)
class Observation:
    """What the car reports in one control cycle."""

    time: float  # [s] sim time
    x: float  # [m] odometry pose
    y: float  # [m]
    yaw: float  # [rad]
    swivel: float  # [rad] measured theta2
    swivel_rate: float  # [rad/s]
    set_point: float  # [rad] controller's swivel set point (after its rate limiter)
    torque: float  # [N m] controller's commanded swivel torque
    pitch: float  # [rad] base_link pitch, REP-103: positive nose down
    roll: float  # [rad]
    imu_yaw: float  # [rad] heading from the IMU's orientation (any fixed offset)
    speed: float  # [m/s] odometry forward speed of base_link


@dataclass(frozen=True)
class Command:
    """A swivel_car_msgs/SwivelCommand."""

    angle: float  # [rad]
    max_rate: float  # [rad/s], 0 = controller default
    drive_speed: float  # [rad/s] at the wheels
    hold: bool
    free: bool = False  # no swivel torque: the load turns the swivel (angle unused)


@dataclass(frozen=True)
class Finish:
    """The climb ends: NONE is success."""

    code: ErrorCode
    message: str


class Climb:
    """
    What the steps share: the plan, the edge, the car's geometry on it, the swivel's outer loop.

    Parameters
    ----------
    p : SwivelCarParams
    config : PlannerConfig
    plan : ClimbPlan
    start : Observation
        The first observation: the request's edge is relative to the car then.
    step_distance, step_yaw : float
        The request's edge. # [m], [rad]

    """

    def __init__(self, p: SwivelCarParams, config: PlannerConfig, plan: ClimbPlan,
                 start: Observation, step_distance: float, step_yaw: float) -> None:
        self.p, self.config, self.plan = p, config, plan
        self.semi_active = plan.procedure == PROCEDURE_SEMI_ACTIVE
        self.origin = Pose2D(start.x, start.y, start.yaw)  # odometry pose when asked
        self.edge = StepEdge.from_request(self.origin, p.wheelbase, step_distance, step_yaw)
        self.yaw_offset = start.imu_yaw - start.yaw  # [rad] IMU minus odometry heading
        self.last: Observation | None = None  # the previous cycle's observation
        self.bias = 0.0  # [rad] outer-loop correction added to the wanted swivel angle
        # [rad] how far the swivel is from what the step wants; None while steering
        self.goal_error: float | None = None
        self.last_command = 0.0  # [rad] swivel angle last sent

    # --- geometry -------------------------------------------------------------------------

    def heading(self, obs: Observation) -> float:
        """Return the car's heading in the odometry frame, from the IMU [rad]."""
        return wrap_angle(obs.imu_yaw - self.yaw_offset)

    def wheel_distance(self, obs: Observation, bx: float, by: float) -> float:
        """
        Signed distance past the edge of a wheel's contact given at rest in base_link [m].

        The rest geometry ignores how the swivel moves the front contacts (a few cm at the
        lift angles); ``lead_margin`` and ``lift_gap`` absorb it.
        """
        pose = Pose2D(obs.x, obs.y, self.heading(obs))
        return self.edge.signed_distance(*pose.transform(bx, by))

    def lifted_wheel_distance(self, obs: Observation) -> float:
        return self.wheel_distance(obs, self.p.wheelbase, self.plan.lifted_side * self.p.h)

    def second_wheel_distance(self, obs: Observation) -> float:
        return self.wheel_distance(obs, self.p.wheelbase, -self.plan.lifted_side * self.p.h)

    def rear_wheel_distance(self, obs: Observation) -> float:
        """Return the distance past the edge of the rear wheel nearer the riser (trailing) [m]."""
        return min(self.wheel_distance(obs, 0.0, self.p.h),
                   self.wheel_distance(obs, 0.0, -self.p.h))

    def backed_up(self, obs: Observation) -> float:
        """Return how far the car is behind where the climb was asked, along its x then [m]."""
        origin = self.origin
        return -((obs.x - origin.x) * math.cos(origin.yaw)
                 + (obs.y - origin.y) * math.sin(origin.yaw))

    # --- the swivel -----------------------------------------------------------------------

    def stand(self) -> Command:
        """Drive 0, the swivel held at the last command."""
        return Command(self.last_command, self.config.swivel_rate, 0.0, True)

    def open_loop(self, angle: float, drive_speed: float, free: bool = False) -> Command:
        """Command ``angle`` as it is, no outer loop (its bias starts again from zero)."""
        self.bias = 0.0
        self.goal_error = None
        self.last_command = angle
        return Command(angle, self.config.swivel_rate, drive_speed, True, free)

    def hold(self, obs: Observation, angle: float, drive_speed: float) -> Command:
        """
        Bring the measured swivel to ``angle`` while driving at ``drive_speed``: the outer loop.

        The bias integrates only once the controller's rate-limited set point has reached the
        last command: while it still ramps, the error is the ramp's, not the load's.
        """
        config = self.config
        error = angle - obs.swivel
        dt = obs.time - self.last.time if self.last is not None else 0.0
        if abs(obs.set_point - self.last_command) < config.swivel_tolerance:
            self.bias = min(config.max_bias, max(
                -config.max_bias, self.bias + config.bias_gain * error * dt))
        self.goal_error = abs(error)
        limit = self.p.swivel_limit
        self.last_command = min(limit, max(-limit, angle + self.bias))
        return Command(self.last_command, config.swivel_rate, drive_speed, True)


class StepBehaviour:
    """
    One step: entered with the observation of that cycle, then updated once a cycle.

    ``quantity`` is what the step's progress follows, from its value on entry to ``goal``.
    ``driving`` steps are watched by NO_PROGRESS.
    """

    step: Step
    driving = False

    def __init__(self, climb: Climb, obs: Observation) -> None:
        self.climb = climb
        self.span = (self.quantity(obs), self.goal())

    def quantity(self, obs: Observation) -> float:
        return obs.swivel

    def goal(self) -> float:
        raise NotImplementedError

    def update(self, obs: Observation) -> Command | Step | Finish:
        raise NotImplementedError

    def watch(self, obs: Observation) -> Finish | None:
        """Return a failure this step looks for beyond the climb's monitors."""
        return None


class _Ramp:
    """A swivel ramp at ``swivel_rate`` from where it was when the step began."""

    def __init__(self, climb: Climb, obs: Observation) -> None:
        self._climb = climb
        limit = climb.p.swivel_limit
        self._since = obs.time  # [s]
        self._start = min(limit, max(-limit, obs.swivel))  # [rad]

    def command(self, obs: Observation, angle: float, drive_speed: float,
                then_hold: bool = False) -> Command:
        """
        Command the ramp towards ``angle`` while driving at ``drive_speed``.

        The set point and the command stay together, so the controller keeps driving. No
        outer loop (``then_hold``: the outer loop once the ramp has reached ``angle``); the
        stall monitor watches the measured swivel's headway on ``angle``.
        """
        climb, start = self._climb, self._start
        travel = climb.config.swivel_rate * (obs.time - self._since)  # [rad]
        if then_hold and travel >= abs(angle - start):
            return climb.hold(obs, angle, drive_speed)
        ramped = start + math.copysign(min(abs(angle - start), travel), angle - start)
        command = climb.open_loop(ramped, drive_speed)
        climb.goal_error = abs(angle - obs.swivel)
        return command


class _Settling:
    """Tells whether the swivel is at a target and at rest for ``settle_time``."""

    def __init__(self, config: PlannerConfig) -> None:
        self._config = config
        self._since: float | None = None  # [s]

    def settled(self, obs: Observation, target: float) -> bool:
        config = self._config
        if (abs(obs.swivel - target) <= config.swivel_tolerance
                and abs(obs.swivel_rate) <= config.settle_rate):
            if self._since is None:
                self._since = obs.time
            return obs.time - self._since >= config.settle_time
        self._since = None
        return False


def _first_move(plan: ClimbPlan) -> Step:
    if plan.reposition:
        return Step.REPOSITION
    return Step.BACK_UP if plan.backup_distance > 0.0 else Step.APPROACH


class Stop(StepBehaviour):
    """Only if the car moves when asked: drive 0, the swivel held, until it stands."""

    step = Step.STOP

    def quantity(self, obs: Observation) -> float:
        return abs(obs.speed)

    def goal(self) -> float:
        return 0.0

    def update(self, obs: Observation) -> Command | Step:
        if abs(obs.speed) <= self.climb.config.stop_speed:
            return _first_move(self.climb.plan)
        return self.climb.stand()


class BackUp(StepBehaviour):
    """
    Only if the plan says so (the step is too close to turn onto the approach).

    Reverse straight, the swivel at 0, until the car is ``plan.backup_distance`` back.
    """

    step = Step.BACK_UP
    driving = True

    def quantity(self, obs: Observation) -> float:
        return self.climb.backed_up(obs)

    def goal(self) -> float:
        return self.climb.plan.backup_distance

    def update(self, obs: Observation) -> Command | Step:
        config = self.climb.config
        if self.climb.backed_up(obs) >= self.goal():
            return Step.APPROACH
        return Command(0.0, config.swivel_rate, -config.approach_speed, True)


_SLOWDOWN = 0.5  # [s] repositioning: the drive slows to reach a segment's end in this time
_CREEP = 0.1  # [1] but not below this share of approach_speed (the drive's friction)


class Reposition(StepBehaviour):
    """
    Only if the plan says so: drive its repositioning path to where the approach can start.

    The plan has one where there is no room for the approach from where the car stands, nor
    after backing up straight.

    Each segment (``reposition`` module): the car stands, the swivel goes to the segment's
    angle (the outer loop, settled), then the car drives at ``approach_speed``, forwards or
    backwards, the swivel held, until it has turned the segment's heading change (the IMU:
    on the tightest circle) or covered its length (odometry: straight). Last the swivel goes
    back to 0 at a standstill. The approach then steers from where the car is, closing on the
    planned heading and crossing whatever the path left over.
    """

    step = Step.REPOSITION

    def __init__(self, climb: Climb, obs: Observation) -> None:
        self._segments = (*climb.plan.reposition, Segment(0.0, 0.0))
        self._index = 0
        self._path = 0.0  # [m] odometry path since the step began
        self._last = (obs.x, obs.y)  # [m]
        # (path [m], heading [rad]) when the segment's drive began; None while it stands
        self._drive: tuple[float, float] | None = None
        self._settling = _Settling(climb.config)
        super().__init__(climb, obs)

    @property
    def driving(self) -> bool:
        return self._drive is not None

    def quantity(self, obs: Observation) -> float:
        return self._path

    def goal(self) -> float:
        return reposition_length(self.climb.plan.reposition)

    def update(self, obs: Observation) -> Command | Step:
        climb = self.climb
        config = climb.config
        self._path += math.hypot(obs.x - self._last[0], obs.y - self._last[1])
        self._last = (obs.x, obs.y)
        segment = self._segments[self._index]
        if self._drive is None:
            if abs(obs.speed) > config.stop_speed or not self._settling.settled(
                    obs, segment.swivel):
                return climb.hold(obs, segment.swivel, 0.0)
            if segment.length == 0.0:
                self._index += 1
                if self._index == len(self._segments):
                    return Step.APPROACH
                return climb.hold(obs, segment.swivel, 0.0)
            self._drive = (self._path, climb.heading(obs))
        start_path, start_heading = self._drive
        if segment.swivel == 0.0:
            remaining = abs(segment.length) - (self._path - start_path)  # [m]
        else:
            curvature = path_curvature(climb.p, segment.swivel)  # [1/m]
            turn = curvature * segment.length  # [rad]
            turned = wrap_angle(climb.heading(obs) - start_heading)
            remaining = (abs(turn) - math.copysign(1.0, turn) * turned) / abs(curvature)
        if remaining <= 0.0:
            self._index += 1
            self._drive = None
            self._settling = _Settling(config)
            return climb.hold(obs, segment.swivel, 0.0)
        # Slowing down over the last part stops the car on the segment's end: at full speed
        # it ran 4 cm on (0.18 rad on the tightest circle) in the sim.
        speed = min(config.approach_speed,
                    max(_CREEP * config.approach_speed, remaining / (climb.p.r * _SLOWDOWN)))
        return climb.hold(obs, segment.swivel, math.copysign(speed, segment.length))


class Approach(StepBehaviour):
    """
    Drive to the lift point, steering to the planned heading (and through its crossing).

    Semi-active: it turns onto the line through the crossing no sooner than the arc of
    ``plan.semi_active_turn`` meets it tangentially (``_turn_in``), and the lift point accepts
    a heading up to twice ``align_tolerance`` more oblique than planned (the steering wheel only
    gets further off the riser: the minimum approach angle is a lower bound), not less.
    """

    step = Step.APPROACH
    driving = True

    def __init__(self, climb: Climb, obs: Observation) -> None:
        super().__init__(climb, obs)
        # (arc radius [m], straight run before it [m]) of the semi-active approach's turn-in
        self._turn = semi_active_turn(climb.p, climb.config) if climb.semi_active \
            else (0.0, 0.0)

    def quantity(self, obs: Observation) -> float:
        return self.climb.lifted_wheel_distance(obs)

    def goal(self) -> float:
        return -self.climb.plan.lead_distance

    def update(self, obs: Observation) -> Command | Step | Finish:
        climb = self.climb
        config, plan = climb.config, climb.plan
        if climb.lifted_wheel_distance(obs) >= self.goal():
            error = plan.approach_heading - climb.edge.relative_heading(climb.heading(obs))
            oblique = (climb.semi_active
                       and 0.0 <= plan.lifted_side * error <= 2.0 * config.align_tolerance)
            if abs(error) > config.align_tolerance and not oblique:
                return Finish(ErrorCode.FAILED,
                              f'reached the lift point {error:.2f} rad off the planned '
                              f'heading (tolerance {config.align_tolerance:.2f} rad)')
            return Step.PRESS if climb.semi_active else Step.LIFT
        return self._steer(obs, self._approach_heading(obs), config.approach_speed)

    def _approach_heading(self, obs: Observation) -> float:
        """
        Return the planned approach heading, corrected towards the planned crossing [rad].

        Corrected only when the step's extent is known (a line through the crossing of the edge
        at that heading).
        """
        climb = self.climb
        plan, config = climb.plan, climb.config
        if plan.crossing is None:
            return plan.approach_heading
        normal = climb.edge.signed_distance(obs.x, obs.y)
        along = climb.edge.along(obs.x, obs.y) - plan.crossing
        heading = plan.approach_heading
        off_line = -math.sin(heading) * normal + math.cos(heading) * along  # [m] left of it
        correction = config.crossing_gain * off_line
        limit = config.max_steer
        if climb.semi_active:
            correction = math.copysign(min(abs(correction), self._turn_in(abs(off_line))),
                                       correction)
        if plan.push_lift or climb.semi_active:
            # Its heading is large: far off the line the car may hold the heading it has
            # and meet the line at an angle, rather than chase it at max_steer to the lift.
            limit = max(limit, abs(heading))
        return heading - min(limit, max(-limit, correction))

    def _turn_in(self, off_line: float) -> float:
        """
        Return the heading [rad] to a line ``off_line`` [m] away that meets it tangentially.

        Straight on while the swivel turns to ``max_steer``, then on the arc
        ``semi_active_turn`` plans with: ``R (1 - cos d) + L sin d = off_line``. The
        semi-active approach's heading is large (0.75-0.94 rad): at ``crossing_gain`` alone the
        car would turn in 0.2 m short of its line and meet it still turning, the swivel at its
        steering limit; the phi < 0 swivel's own yaw, against the turn, delays every turn.
        """
        radius, delay = self._turn
        norm = math.hypot(radius, delay)
        return (math.acos(max(-1.0, min(1.0, (radius - off_line) / norm)))
                - math.atan2(delay, radius))

    def _steer(self, obs: Observation, heading: float, drive_speed: float) -> Command:
        """
        Drive at ``drive_speed`` steering towards ``heading`` (to the edge normal).

        For phi < 0 the swivel's own move yaws the car against the turn it steers
        (``dynamics.swivel_pose_drift``: 0.22 rad the other way on the phi < 0 design for a
        0.35 rad steer), so straightening the swivel turns the car further: the loop steers
        on the heading the car will have once the swivel is back at 0 (else the approach
        overshoots its heading by 0.25 rad and swings on). For phi > 0 the move yaws the car
        with the turn and is left alone.
        """
        climb = self.climb
        current = climb.edge.relative_heading(climb.heading(obs))
        if climb.p.phi < 0.0:
            current -= float(dynamics.swivel_pose_drift(climb.p, 0.0, obs.swivel)[2])
        error = heading - current
        limit = climb.config.max_steer
        steering = min(limit, max(-limit, climb.config.heading_gain * error))
        return climb.open_loop(float(kinematics.swivel_for_steering(climb.p, steering)),
                               drive_speed)


class Press(StepBehaviour):
    """
    Semi-active only: drive on at ``climb_speed``, the swivel where it is, to the riser.

    Until the riser stops the lifted wheel (odometry speed below ``stop_speed``), or odometry
    has that wheel ``lift_gap`` past where it meets the riser (it rolled up a low step by
    itself, or the edge is not where asked). Not watched by NO_PROGRESS: the car stands at the
    riser by design.
    """

    step = Step.PRESS

    def quantity(self, obs: Observation) -> float:
        return self.climb.lifted_wheel_distance(obs)

    def goal(self) -> float:
        return -(self.climb.plan.lead_distance - self.climb.config.lift_gap)

    def update(self, obs: Observation) -> Command | Step:
        climb = self.climb
        config = climb.config
        if abs(obs.speed) <= config.stop_speed or climb.lifted_wheel_distance(obs) \
                >= -(climb.plan.lead_distance - 2.0 * config.lift_gap):
            return Step.LIFT
        return climb.open_loop(climb.last_command, config.climb_speed)


class Lift(StepBehaviour):
    """Stop; swivel to the plan's angle: the leading front wheel rises above the step."""

    step = Step.LIFT

    def __init__(self, climb: Climb, obs: Observation) -> None:
        super().__init__(climb, obs)
        self._settling = _Settling(climb.config)

    def goal(self) -> float:
        return self.climb.plan.swivel_angle

    def update(self, obs: Observation) -> Command | Step:
        if self._settling.settled(obs, self.goal()):
            return Step.ADVANCE
        return self.climb.hold(obs, self.goal(), 0.0)


class DrivenLift(StepBehaviour):
    """
    Semi-active LIFT: keep driving at ``climb_speed`` while the swivel ramps to the angle.

    The drive presses the wheel against the riser and its push does part of the lift (thesis
    eqs. 86-91). Ends when the measured swivel is within ``swivel_tolerance`` of the angle;
    its headway is watched by STALL, not NO_PROGRESS.
    """

    step = Step.LIFT

    def __init__(self, climb: Climb, obs: Observation) -> None:
        super().__init__(climb, obs)
        self._ramp = _Ramp(climb, obs)

    def goal(self) -> float:
        return self.climb.plan.swivel_angle

    def update(self, obs: Observation) -> Command | Step:
        climb = self.climb
        side, config = climb.plan.lifted_side, climb.config
        if side * obs.swivel >= side * self.goal() - config.swivel_tolerance:
            return Step.ADVANCE
        return self._ramp.command(obs, self.goal(), config.climb_speed, then_hold=True)


class Advance(StepBehaviour):
    """
    Drive, the swivel held, until the lifted wheel is ``lead_margin`` over the step.

    Push-lift (the grounded wheel leads to the riser): until the point where the lifted wheel
    will land (``plan.lifted_point``) is ``push_margin`` past the edge.
    """

    step = Step.ADVANCE
    driving = True

    def quantity(self, obs: Observation) -> float:
        climb = self.climb
        if climb.plan.push_lift:
            return climb.wheel_distance(obs, *climb.plan.lifted_point)
        return climb.lifted_wheel_distance(obs)

    def goal(self) -> float:
        config = self.climb.config
        return config.push_margin if self.climb.plan.push_lift else config.lead_margin

    def update(self, obs: Observation) -> Command | Step:
        if self.quantity(obs) >= self.goal():
            return Step.SET_DOWN
        climb = self.climb
        return climb.hold(obs, climb.plan.swivel_angle, climb.config.climb_speed)


class SetDown(StepBehaviour):
    """
    Stop; swivel towards the other side until the second front wheel is clear of the step.

    The lifted wheel lands on the step, then the swivel lifts the front of the car until the
    other front wheel is ``clearance_margin`` above it: the swivel at or beyond
    ``plan.second_swivel_angle``. Push-lift: it drives at ``set_down_speed`` while the command
    ramps at ``swivel_rate`` (the controller drives at full speed only while its swivel error is
    below ``slowdown_start``), so that the rear axle follows the front as it pitches up
    instead of the wheel on the top sliding back off the edge.
    """

    step = Step.SET_DOWN

    def __init__(self, climb: Climb, obs: Observation) -> None:
        super().__init__(climb, obs)
        self._ramp = _Ramp(climb, obs)

    def goal(self) -> float:
        return self.climb.plan.second_swivel_angle

    def update(self, obs: Observation) -> Command | Step:
        climb = self.climb
        side, config = climb.plan.lifted_side, climb.config
        if side * obs.swivel <= side * self.goal() + config.swivel_tolerance:
            return Step.SECOND_ADVANCE
        if climb.plan.push_lift:
            return self._ramp.command(obs, self.goal(), config.set_down_speed)
        return climb.hold(obs, self.goal(), 0.0)


class SecondAdvance(StepBehaviour):
    """Drive, the swivel held, until the second front wheel is ``lead_margin`` over the step."""

    step = Step.SECOND_ADVANCE
    driving = True

    def quantity(self, obs: Observation) -> float:
        return self.climb.second_wheel_distance(obs)

    def goal(self) -> float:
        return self.climb.config.lead_margin

    def update(self, obs: Observation) -> Command | Step:
        climb = self.climb
        if climb.second_wheel_distance(obs) >= self.goal():
            return Step.SECOND_SET_DOWN
        return climb.hold(obs, climb.plan.second_swivel_angle, climb.config.climb_speed)


class SecondSetDown(StepBehaviour):
    """Stop; swivel to 0: the second front wheel lands."""

    step = Step.SECOND_SET_DOWN

    def __init__(self, climb: Climb, obs: Observation) -> None:
        super().__init__(climb, obs)
        self._settling = _Settling(climb.config)

    def goal(self) -> float:
        return 0.0

    def update(self, obs: Observation) -> Command | Step:
        if self._settling.settled(obs, 0.0):
            return Step.REAR
        return self.climb.hold(obs, 0.0, 0.0)


class Rear(StepBehaviour):
    """
    Drive at ``rear_speed``, the swivel free, until the rear wheels are past the edge, level.

    The rear axle has no lift: it climbs by traction and momentum only. Free, the swivel lets
    the rear T roll under the front one, so each rear wheel meets the riser with its own load;
    held, it twists a rear wheel off its traction (docs/climbing_design.md). Fails when
    odometry has the rear axle ``rear_slip_allowance`` past the edge while the IMU still shows
    the car pitched (it did not climb), or the car comes level with the rear wheels short of the
    riser (the front came down). ``watch``: the wheels slipping, the IMU's heading parting from
    the odometry's by ``slip_yaw_tolerance`` since this step began (NO_PROGRESS: the car does
    not go where odometry says, and a front slid back off the step would look level and past
    the edge by odometry).
    """

    step = Step.REAR
    driving = True

    def __init__(self, climb: Climb, obs: Observation) -> None:
        super().__init__(climb, obs)
        p, plan = climb.p, climb.plan
        # [rad] level on top: well below the pitch of the car with only its front on the step
        self._level = min(climb.config.level_tolerance,
                          0.5 * math.asin(min(1.0, plan.step_height / p.wheelbase)))
        self._front_seen_up = False  # the IMU showed the car nose-up (front on the step)
        self._slip_ref = wrap_angle(climb.heading(obs) - obs.yaw)  # [rad] IMU minus odometry

    def quantity(self, obs: Observation) -> float:
        return self.climb.rear_wheel_distance(obs)

    def goal(self) -> float:
        return self.climb.config.rest_margin

    def watch(self, obs: Observation) -> Finish | None:
        slip = wrap_angle(self.climb.heading(obs) - obs.yaw - self._slip_ref)
        if abs(slip) > self.climb.config.slip_yaw_tolerance:
            return Finish(ErrorCode.NO_PROGRESS,
                          f'the wheels slip: the IMU heading has turned {slip:+.2f} rad away '
                          f"from the odometry's in {self.step.name}")
        return None

    def update(self, obs: Observation) -> Command | Step | Finish:
        climb = self.climb
        config = climb.config
        rear = climb.rear_wheel_distance(obs)
        level = abs(obs.pitch) <= self._level
        if not level:
            self._front_seen_up = True
        if level and abs(obs.roll) <= self._level and self._front_seen_up \
                and rear < -(climb.p.r + _REAR_ODOMETRY_LAG):
            # Level again while the rear wheels are still short of the riser: the front
            # came down off the step (it slid back or sideways), the rear did not climb.
            # Not while rolled: one rear wheel up halves the pitch. Odometry lags the
            # climbing wheels: a car level on top of a 2-3 cm step can look 0.08 m short.
            return Finish(ErrorCode.FAILED,
                          f'the front wheels came down off the step while the rear axle was '
                          f'still {-rear:.2f} m short of the edge')
        if rear >= config.rest_margin and level and not self._front_seen_up:
            # Odometry counts wheels spinning against the riser as travel: level all along,
            # the front never got up.
            return Finish(ErrorCode.FAILED,
                          f'the front wheels never got on top: the car stayed level while '
                          f'odometry put the rear axle {rear:.2f} m past the edge (the wheels '
                          f'spun against the riser)')
        if rear >= config.rest_margin and level:
            # The rear wheels leave the riser at speed: stop on the top face before calling
            # it done, the swivel held so the car neither turns nor twists a wheel up.
            climb.last_command = obs.swivel
            return Step.STOP_ON_TOP
        if rear >= config.rest_margin + config.rear_slip_allowance:
            return Finish(ErrorCode.FAILED,
                          f'the front wheels are on top but the rear axle did not climb: '
                          f'odometry puts it {rear:.2f} m past the edge while the pitch is '
                          f'still {obs.pitch:.3f} rad (the rear wheels slip; they climb by '
                          f'traction only)')
        return climb.open_loop(obs.swivel, config.rear_speed, free=True)


class StopOnTop(StepBehaviour):
    """
    Drive 0, the swivel held, until the car stands, still; done if it is then level.

    Standing: odometry's speed below ``stop_speed`` and the IMU's pitch and roll steady for
    ``settle_time``. Odometry's speed alone does not say the car stands: a rear wheel that rode
    up onto the riser's corner stops turning while the car still rocks on it, and the wheels
    can stop just as the rocking car passes level (in the sim on 0.09 m steps: level for an
    instant, rolled 0.13-0.31 rad at rest).
    """

    step = Step.STOP_ON_TOP

    def __init__(self, climb: Climb, obs: Observation) -> None:
        super().__init__(climb, obs)
        # (since [s], pitch low, high, roll low, high [rad]) of the IMU while the wheels stand
        self._attitude_window: tuple[float, float, float, float, float] | None = None
        self._first_stop: Observation | None = None  # the first with the wheels standing

    def quantity(self, obs: Observation) -> float:
        return abs(obs.speed)

    def goal(self) -> float:
        return 0.0

    def update(self, obs: Observation) -> Command | Finish:
        climb = self.climb
        config = climb.config
        if abs(obs.speed) > config.stop_speed:
            self._attitude_window = None
            return climb.stand()
        if self._first_stop is None:
            self._first_stop = obs
        if not self._attitude_steady(obs):
            # The wheels stand but the body still tips: judged once it stops too.
            return climb.stand()
        # Roll gets twice the pitch's tolerance: the held swivel twists the car a little.
        rest = config.rest_tolerance
        if abs(obs.pitch) > rest or abs(obs.roll) > 2.0 * rest:
            return Finish(ErrorCode.FAILED, self._not_on_top_message(obs))
        return Finish(ErrorCode.NONE, 'climbed: all four wheels on top of the step, at rest')

    def _attitude_steady(self, obs: Observation) -> bool:
        """
        Tell whether the IMU's pitch and roll have held steady for ``settle_time``.

        Steady: within ``settle_rate * settle_time`` of each other (the swivel's at-rest rate
        and time, applied to the body).
        """
        config = self.climb.config
        band = config.settle_rate * config.settle_time  # [rad]
        window = self._attitude_window
        if window is not None:
            since, low_pitch, high_pitch, low_roll, high_roll = window
            low_pitch, high_pitch = min(low_pitch, obs.pitch), max(high_pitch, obs.pitch)
            low_roll, high_roll = min(low_roll, obs.roll), max(high_roll, obs.roll)
            if high_pitch - low_pitch <= band and high_roll - low_roll <= band:
                self._attitude_window = (since, low_pitch, high_pitch, low_roll, high_roll)
                return obs.time - since >= config.settle_time
        self._attitude_window = (obs.time, obs.pitch, obs.pitch, obs.roll, obs.roll)
        return config.settle_time <= 0.0

    def _not_on_top_message(self, obs: Observation) -> str:
        """Describe what the planner saw of a car standing tilted after the rear step."""
        message = (f'the car came to rest pitched {obs.pitch:.3f} rad, rolled '
                   f'{obs.roll:.3f} rad although odometry puts the rear wheels '
                   f'{self.climb.rear_wheel_distance(obs):.2f} m past the edge: a wheel is not '
                   f'on top')
        first, rest = self._first_stop, self.climb.config.rest_tolerance
        if first is not None and first is not obs and abs(first.pitch) <= rest \
                and abs(first.roll) <= 2.0 * rest:
            message += (f' (when the wheels stopped it looked level, pitched '
                        f'{first.pitch:.3f} rad, rolled {first.roll:.3f} rad, then it tipped '
                        f'for {obs.time - first.time:.2f} s with the wheels standing: a rear '
                        f'wheel had not come up, its spin counted as travel by odometry)')
        return message


def _lift(climb: Climb, obs: Observation) -> StepBehaviour:
    return DrivenLift(climb, obs) if climb.semi_active else Lift(climb, obs)


# Which class runs which step; DONE is the end, no step.
BEHAVIOURS: dict[Step, Callable[[Climb, Observation], StepBehaviour]] = {
    Step.STOP: Stop, Step.BACK_UP: BackUp, Step.REPOSITION: Reposition,
    Step.APPROACH: Approach, Step.PRESS: Press,
    Step.LIFT: _lift, Step.ADVANCE: Advance, Step.SET_DOWN: SetDown,
    Step.SECOND_ADVANCE: SecondAdvance, Step.SECOND_SET_DOWN: SecondSetDown, Step.REAR: Rear,
    Step.STOP_ON_TOP: StopOnTop}


def enter(step: Step, climb: Climb, obs: Observation) -> StepBehaviour:
    """
    Build the behaviour of ``step`` on entering it.

    Raises
    ------
    LookupError
        ``step`` has no behaviour in ``BEHAVIOURS``.

    """
    try:
        behaviour = BEHAVIOURS[step]
    except KeyError:
        raise LookupError(f'the climb has no behaviour for step {step.name}') from None
    return behaviour(climb, obs)


def first_step(climb: Climb, obs: Observation) -> Step:
    """Return the step a climb starts in: STOP if the car moves, else its first move."""
    if abs(obs.speed) > climb.config.stop_speed:
        climb.last_command = obs.swivel
        return Step.STOP
    return _first_move(climb.plan)
