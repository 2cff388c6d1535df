"""
The climb as a pure state machine: observations in, swivel commands and feedback out.

One ``update`` per control cycle (the node calls it from a sim-time timer). Steps (and the
action phase each one reports)::

    STOP             only if the car is moving when asked: drive 0, the swivel
                     held, until odometry says it stands (the edge stays where
                     the request put it, relative to the car when asked)       APPROACH
    BACK_UP          only if the plan says so (the step is too close to turn
                     onto the approach): reverse straight, the swivel at 0,
                     until the car is ``plan.backup_distance`` back            APPROACH
    APPROACH         drive to the lift point, steering to the planned heading   APPROACH
    PRESS            semi-active only (below): drive on until the lifted wheel
                     is stopped by the riser                                    APPROACH
    LIFT             stop; swivel to the plan's angle: the leading front wheel
                     rises above the step                                       LIFT
    ADVANCE          drive, swivel held, until that wheel is over the step      ADVANCE
    SET_DOWN         stop; swivel towards the other side: the wheel lands on
                     the step, then the swivel lifts the front of the car until
                     the other front wheel is ``clearance_margin`` above it     SET_DOWN
    SECOND_ADVANCE   drive until the second front wheel is over the step        CLIMB_REST
    SECOND_SET_DOWN  stop; swivel to 0: the second wheel lands                  CLIMB_REST
    REAR             drive at ``rear_speed``, the swivel free (no torque), until
                     the rear wheels are past the edge and the car is level;
                     the rear axle has no lift, it climbs by traction and
                     momentum only                                              CLIMB_REST
    STOP_ON_TOP      drive 0, the swivel held where it is, until odometry says
                     the car stands and the IMU's pitch and roll have been
                     still for ``settle_time``; done if it is still level       CLIMB_REST

A semi-active plan (``PROCEDURE_SEMI_ACTIVE``, phi < 0, plan module) puts PRESS between
APPROACH and LIFT and changes LIFT: the car does not stop. PRESS drives on at ``climb_speed``,
the swivel where it is, until the riser stops the lifted wheel (odometry speed below
``stop_speed``; or odometry has that wheel ``lift_gap`` past where it meets the riser). LIFT
keeps driving while the swivel ramps at ``swivel_rate`` to the plan's angle (then the outer
loop below closes the rest), so the drive presses the wheel against the riser and its push
does part of the lift (thesis eqs. 86-91). LIFT ends when the measured swivel is within
``swivel_tolerance`` of that angle. Neither step is watched by NO_PROGRESS (the car stands
at the riser by design): a wheel that never meets a riser ends PRESS by odometry, and LIFT's
swivel headway is watched by STALL. Its APPROACH turns onto the line through the planned
crossing no sooner than the arc of ``plan.semi_active_turn`` meets it tangentially
(``_turn_in``), and the lift point accepts a heading up to twice ``align_tolerance`` more
oblique than planned (the steering wheel only gets further off the riser), not less.

A push-lift plan (``plan.push_lift``: the grounded wheel leads to the riser, plan module)
changes two steps: ADVANCE ends with the point where the lifted wheel will land on the step
(``plan.lifted_point``) ``push_margin`` past the edge, and SET_DOWN drives at
``set_down_speed`` while it ramps its command at ``swivel_rate`` (the controller drives at
full speed only while its swivel error is below ``slowdown_start``), so that the rear axle
follows the front as it pitches up instead of the wheel on the top sliding back off the edge.

Every step but APPROACH wants the *measured* swivel at an angle. Under load (a wheel lifted,
or the front of the car lifted with one wheel on the step) the controller's PID settles short
of its set point (measured in the sim: up to 0.3 rad with the thesis gains and an integral
that only acts within 0.1 rad of the set point). So the planner closes an outer loop: it
commands the wanted angle plus a bias that integrates the remaining error (``bias_gain``,
at most ``max_bias``) once the controller's set point has caught up with the command, the
way an operator would push the stick further.

Monitors, every cycle: time allowance (TIMEOUT), nose-up pitch near the tip-over rule
(TIP_OVER_ABORT), the swivel not closing on a wanted angle (STALL), no path length while
driving (NO_PROGRESS), and, while the rear axle climbs, the wheels slipping: the IMU's
heading parting from the odometry's by ``slip_yaw_tolerance`` since the rear step began
(NO_PROGRESS too: the car does not go where odometry says; without this check a car whose
front slid back off the step looked level and "past the edge" by odometry, a false success
seen in the sim at 0.22 m). The rear axle failing to climb (odometry past the edge by
``rear_slip_allowance`` while the IMU still shows the car pitched) ends with FAILED, and so
does the car coming level while the rear wheels are still short of the riser (the front came
down). Any abort stops the drive and holds the swivel where it is.

The heading always comes from the IMU, the position from odometry: the wheels skid when the
swivel turns at a standstill, and odometry's heading then drifts (0.3 rad seen in the sim).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
import math

from swivel_car_model import dynamics, kinematics
from swivel_car_model.params import SwivelCarParams

from swivel_car_planner.core.codes import ErrorCode, Phase
from swivel_car_planner.core.config import PlannerConfig
from swivel_car_planner.core.geometry import Pose2D, StepEdge, wrap_angle
from swivel_car_planner.core.plan import ClimbPlan, PROCEDURE_SEMI_ACTIVE, semi_active_turn


class Step(Enum):
    """Internal steps of the climb: (action phase, share of the progress at its start)."""

    STOP = (Phase.APPROACH, 0.0)
    BACK_UP = (Phase.APPROACH, 0.02)
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


_STEPS = list(Step)
# [m] how far odometry puts the rear wheels behind where they are while they climb
# (measured up to 0.09 m)
_REAR_ODOMETRY_LAG = 0.1
_DRIVING = (Step.BACK_UP, Step.APPROACH, Step.ADVANCE, Step.SECOND_ADVANCE, Step.REAR)


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
class Feedback:
    phase: Phase
    phase_name: str  # the phase, and within CLIMB_REST the step
    progress: float  # [1]
    pitch: float  # [rad]
    roll: float  # [rad]
    swivel_angle: float  # [rad]
    swivel_torque: float  # [N m]
    distance_to_edge: float  # [m] front axle contact to the edge, positive before it


@dataclass(frozen=True)
class Outcome:
    success: bool
    error_code: ErrorCode
    message: str
    duration: float  # [s]
    peak_torque: float  # [N m]
    energy: float  # [J]
    max_pitch: float  # [rad]
    distance_travelled: float  # [m]


class ClimbStateMachine:
    """
    Runs one planned climb. Call ``update`` every control cycle until ``outcome`` is set.

    Parameters
    ----------
    p : SwivelCarParams
    config : PlannerConfig
    plan : ClimbPlan
        From ``make_plan``.
    step_distance, step_yaw : float
        The request's edge, relative to the car at the first observation. # [m], [rad]
    time_allowance : float
        Sim time after which the climb aborts with TIMEOUT; 0 = the config's. # [s]

    """

    def __init__(self, p: SwivelCarParams, config: PlannerConfig, plan: ClimbPlan,
                 step_distance: float, step_yaw: float, time_allowance: float = 0.0) -> None:
        self._p = p
        self._config = config
        self._plan = plan
        self._semi_active = plan.procedure == PROCEDURE_SEMI_ACTIVE
        # (arc radius [m], straight run before it [m]) of the semi-active approach's turn-in
        self._turn = semi_active_turn(p, config) if self._semi_active else (0.0, 0.0)
        self._step_distance = step_distance
        self._step_yaw = step_yaw
        self._allowance = time_allowance if time_allowance > 0.0 else config.time_allowance
        # Level on top: well below the pitch of the car with only its front on the step.
        self._level = min(config.level_tolerance,
                          0.5 * math.asin(min(1.0, plan.step_height / p.wheelbase)))
        self._step = Step.APPROACH
        self._edge: StepEdge | None = None
        self._origin = Pose2D(0.0, 0.0, 0.0)  # odometry pose when the climb was asked
        self._start_time = 0.0  # [s]
        self._last: Observation | None = None
        self._path = 0.0  # [m]
        self._yaw_offset = 0.0  # [rad] IMU heading minus odometry heading at the start
        self._slip_ref = 0.0  # [rad] IMU minus odometry heading when the rear axle started
        self._front_seen_up = False  # the IMU showed the car nose-up (front on the step)
        self._peak_torque = 0.0  # [N m]
        self._energy = 0.0  # [J]
        self._max_pitch = 0.0  # [rad]
        self._progress_ref = (0.0, 0.0)  # (time [s], path [m]) of the last progress
        # [rad] how far the swivel is from what the step wants; None while steering
        self._goal_error: float | None = None
        self._stall_ref = (0.0, math.inf)  # (time [s], best error [rad]) of the last headway
        self._at_rest_since: float | None = None
        # STOP_ON_TOP: (since [s], pitch low, high, roll low, high [rad]) of the IMU while the
        # wheels stand, and the first observation with them standing
        self._attitude_window: tuple[float, float, float, float, float] | None = None
        self._first_stop: Observation | None = None
        self._span = (0.0, 1.0)  # (start, end) of the quantity a step's progress follows
        self._cancel_requested = False
        self._hold_angle = 0.0  # [rad] swivel held after a failure
        self._bias = 0.0  # [rad] outer-loop correction added to the wanted swivel angle
        self._ramp_start = (0.0, 0.0)  # (time [s], swivel [rad]) when the step began
        self._last_command = 0.0  # [rad] swivel angle last sent
        self.outcome: Outcome | None = None
        self.feedback = Feedback(Phase.PLANNING, 'PLANNING', 0.0, 0.0, 0.0, 0.0, 0.0,
                                 step_distance)

    @property
    def phase(self) -> Phase:
        return self._step.phase

    @property
    def step(self) -> Step:
        return self._step

    def cancel(self) -> None:
        """End the climb at the next ``update``: stop the drive and hold the swivel."""
        self._cancel_requested = True

    def abort(self, code: ErrorCode, message: str) -> Command | None:
        """
        End the climb between observations (its inputs stopped).

        The drive stops and the swivel holds where it was last seen; None if it was never
        observed.
        """
        if self.outcome is not None:
            return self._final_command()
        if self._last is None:
            self.outcome = Outcome(False, code, message, 0.0, 0.0, 0.0, 0.0, 0.0)
            return None
        return self._finish(self._last, code, message)

    def update(self, obs: Observation) -> Command:
        """Advance the climb by one observation; returns the command to send now."""
        if self.outcome is not None:
            return self._final_command()
        if self._edge is None:
            self._start(obs)
        self._measure(obs)
        failure = self._monitor(obs)
        if failure is not None:
            return self._finish(obs, *failure)
        command = self._advance(obs)
        self._last = obs
        if self.outcome is not None:
            return self._final_command()
        self._publish_feedback(obs)
        return command

    # --- steps ----------------------------------------------------------------------------

    def _advance(self, obs: Observation) -> Command:
        config, plan = self._config, self._plan
        side = plan.lifted_side
        step = self._step
        if step == Step.STOP:
            if abs(obs.speed) <= config.stop_speed:
                return self._enter(self._first_move(), obs)
            return Command(self._last_command, config.swivel_rate, 0.0, True)
        if step == Step.BACK_UP:
            if self._backed_up(obs) >= plan.backup_distance:
                return self._enter(Step.APPROACH, obs)
            return Command(0.0, config.swivel_rate, -config.approach_speed, True)
        if step == Step.APPROACH:
            if self._lifted_wheel_distance(obs) >= -plan.lead_distance:
                heading = self._edge.relative_heading(self._heading(obs))
                error = plan.approach_heading - heading
                # Semi-active: more oblique only moves the steering wheel further off the
                # riser (the minimum approach angle is a lower bound): twice the tolerance.
                oblique = (self._semi_active
                           and 0.0 <= side * error <= 2.0 * config.align_tolerance)
                if abs(error) > config.align_tolerance and not oblique:
                    return self._finish(
                        obs, ErrorCode.FAILED,
                        f'reached the lift point {error:.2f} rad off the planned heading '
                        f'(tolerance {config.align_tolerance:.2f} rad)')
                return self._enter(Step.PRESS if self._semi_active else Step.LIFT, obs)
            return self._steer(obs, self._approach_heading(obs), config.approach_speed)
        if step == Step.PRESS:
            # Stopped by the riser, or odometry has the wheel lift_gap past where it meets
            # it (it rolled up a low step by itself, or the edge is not where asked).
            if abs(obs.speed) <= config.stop_speed or self._lifted_wheel_distance(obs) \
                    >= -(plan.lead_distance - 2.0 * config.lift_gap):
                return self._enter(Step.LIFT, obs)
            return self._open_loop(self._last_command, config.climb_speed)
        if step == Step.LIFT and self._semi_active:
            # Drive and swivel together: the riser's push on the driven wheel helps the lift.
            if side * obs.swivel >= side * plan.swivel_angle - config.swivel_tolerance:
                return self._enter(Step.ADVANCE, obs)
            return self._ramp(obs, plan.swivel_angle, config.climb_speed, then_hold=True)
        if step == Step.LIFT:
            if self._settled(obs, plan.swivel_angle):
                return self._enter(Step.ADVANCE, obs)
            return self._hold(obs, plan.swivel_angle, 0.0)
        if step == Step.ADVANCE:
            if self._advance_distance(obs) >= self._advance_goal():
                return self._enter(Step.SET_DOWN, obs)
            return self._hold(obs, plan.swivel_angle, config.climb_speed)
        if step == Step.SET_DOWN:
            # The wheel lands, then the swivel lifts the front until the second wheel is
            # clearance_margin up: the swivel at or beyond plan.second_swivel_angle.
            if side * obs.swivel <= side * plan.second_swivel_angle + config.swivel_tolerance:
                return self._enter(Step.SECOND_ADVANCE, obs)
            if plan.push_lift:
                return self._ramp(obs, plan.second_swivel_angle, config.set_down_speed)
            return self._hold(obs, plan.second_swivel_angle, 0.0)
        if step == Step.SECOND_ADVANCE:
            if self._second_wheel_distance(obs) >= config.lead_margin:
                return self._enter(Step.SECOND_SET_DOWN, obs)
            return self._hold(obs, plan.second_swivel_angle, config.climb_speed)
        if step == Step.SECOND_SET_DOWN:
            if self._settled(obs, 0.0):
                return self._enter(Step.REAR, obs)
            return self._hold(obs, 0.0, 0.0)
        if step == Step.STOP_ON_TOP:
            if abs(obs.speed) > config.stop_speed:
                self._attitude_window = None
                return Command(self._last_command, config.swivel_rate, 0.0, True)
            if self._first_stop is None:
                self._first_stop = obs
            if not self._attitude_steady(obs):
                # The wheels stand but the body still tips: judged once it stops too.
                return Command(self._last_command, config.swivel_rate, 0.0, True)
            # Roll gets twice the pitch's tolerance: the held swivel twists the car a little.
            rest = config.rest_tolerance
            if abs(obs.pitch) > rest or abs(obs.roll) > 2.0 * rest:
                return self._finish(obs, ErrorCode.FAILED, self._not_on_top_message(obs))
            return self._finish(obs, ErrorCode.NONE,
                                'climbed: all four wheels on top of the step, at rest')
        # REAR
        rear = self._rear_wheel_distance(obs)
        level = abs(obs.pitch) <= self._level
        if not level:
            self._front_seen_up = True
        if level and abs(obs.roll) <= self._level and self._front_seen_up \
                and rear < -(self._p.r + _REAR_ODOMETRY_LAG):
            # Level again while the rear wheels are still short of the riser: the front
            # came down off the step (it slid back or sideways), the rear did not climb.
            # Not while rolled: one rear wheel up halves the pitch. Odometry lags the
            # climbing wheels: a car level on top of a 2-3 cm step looked 0.08 m short.
            return self._finish(
                obs, ErrorCode.FAILED,
                f'the front wheels came down off the step while the rear axle was still '
                f'{-rear:.2f} m short of the edge')
        if rear >= config.rest_margin and level and not self._front_seen_up:
            # Odometry counts wheels spinning against the riser as travel: level all along,
            # the front never got up (seen at 24-26 cm, once called "climbed").
            return self._finish(
                obs, ErrorCode.FAILED,
                f'the front wheels never got on top: the car stayed level while odometry put '
                f'the rear axle {rear:.2f} m past the edge (the wheels spun against the riser)')
        if rear >= config.rest_margin and level:
            # The rear wheels leave the riser at speed: stop on the top face before calling
            # it done, the swivel held so the car neither turns nor twists a wheel up.
            self._last_command = obs.swivel
            return self._enter(Step.STOP_ON_TOP, obs)
        if rear >= config.rest_margin + config.rear_slip_allowance:
            return self._finish(
                obs, ErrorCode.FAILED,
                f'the front wheels are on top but the rear axle did not climb: odometry '
                f'puts it {rear:.2f} m past the edge while the pitch is still {obs.pitch:.3f} '
                f'rad (the rear wheels slip; they climb by traction only)')
        # Free, the swivel lets the rear T roll under the front one, so each rear wheel
        # meets the riser with its own load; held, it twisted a rear wheel off its traction
        # (docs/climbing_design.md).
        return self._open_loop(obs.swivel, config.rear_speed, free=True)

    def _attitude_steady(self, obs: Observation) -> bool:
        """
        Tell whether the IMU's pitch and roll have held steady for ``settle_time``.

        Steady: within ``settle_rate * settle_time`` of each other (the swivel's at-rest rate
        and time, applied to the body).

        Odometry's speed alone does not say the car stands: a rear wheel that rode up onto
        the riser's corner stops turning while the car still rocks on it, and the wheels can
        stop just as the rocking car passes level (measured in the sim on 0.09 m steps: level
        for an instant, rolled 0.13 and 0.31 rad once at rest).
        """
        config = self._config
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
                   f'{self._rear_wheel_distance(obs):.2f} m past the edge: a wheel is not on '
                   f'top')
        first, rest = self._first_stop, self._config.rest_tolerance
        if first is not None and first is not obs and abs(first.pitch) <= rest \
                and abs(first.roll) <= 2.0 * rest:
            message += (f' (when the wheels stopped it looked level, pitched '
                        f'{first.pitch:.3f} rad, rolled {first.roll:.3f} rad, then it tipped '
                        f'for {obs.time - first.time:.2f} s with the wheels standing: a rear '
                        f'wheel had not come up, its spin counted as travel by odometry)')
        return message

    def _first_move(self) -> Step:
        return Step.BACK_UP if self._plan.backup_distance > 0.0 else Step.APPROACH

    def _backed_up(self, obs: Observation) -> float:
        """Return how far the car is behind where the climb was asked, along its x then [m]."""
        origin = self._origin
        return -((obs.x - origin.x) * math.cos(origin.yaw)
                 + (obs.y - origin.y) * math.sin(origin.yaw))

    def _approach_heading(self, obs: Observation) -> float:
        """
        Return the planned approach heading, corrected towards the planned crossing [rad].

        Corrected only when the step's extent is known (a line through the crossing of the edge
        at that heading).
        """
        plan = self._plan
        if plan.crossing is None:
            return plan.approach_heading
        normal = self._edge.signed_distance(obs.x, obs.y)
        along = self._edge.along(obs.x, obs.y) - plan.crossing
        heading = plan.approach_heading
        off_line = -math.sin(heading) * normal + math.cos(heading) * along  # [m] left of it
        correction = self._config.crossing_gain * off_line
        limit = self._config.max_steer
        if self._semi_active:
            correction = math.copysign(min(abs(correction), self._turn_in(abs(off_line))),
                                       correction)
        if plan.push_lift or self._semi_active:
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
        car turned in 0.2 m short of its line and met it still turning, the swivel at its
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
        on the heading the car will have once the swivel is back at 0 (without it the
        approach overshot its heading by 0.25 rad and swung on). For phi > 0 the move yaws
        the car with the turn and is left alone.
        """
        current = self._edge.relative_heading(self._heading(obs))
        if self._p.phi < 0.0:
            current -= float(dynamics.swivel_pose_drift(self._p, 0.0, obs.swivel)[2])
        error = heading - current
        limit = self._config.max_steer
        steering = min(limit, max(-limit, self._config.heading_gain * error))
        return self._open_loop(float(kinematics.swivel_for_steering(self._p, steering)),
                               drive_speed)

    def _open_loop(self, angle: float, drive_speed: float, free: bool = False) -> Command:
        """Command ``angle`` as it is, no outer loop (its bias starts again from zero)."""
        self._bias = 0.0
        self._goal_error = None
        self._last_command = angle
        return Command(angle, self._config.swivel_rate, drive_speed, True, free)

    def _ramp(self, obs: Observation, angle: float, drive_speed: float,
              then_hold: bool = False) -> Command:
        """
        Command a ramp at ``swivel_rate`` towards ``angle`` while driving at ``drive_speed``.

        From the swivel where the step began: the set point and the command stay together, so
        the controller keeps driving. No outer loop (``then_hold``: the outer loop of ``_hold``
        once the ramp has reached ``angle``); the stall monitor watches the measured swivel's
        headway on ``angle``.
        """
        since, start = self._ramp_start
        travel = self._config.swivel_rate * (obs.time - since)  # [rad]
        if then_hold and travel >= abs(angle - start):
            return self._hold(obs, angle, drive_speed)
        ramped = start + math.copysign(min(abs(angle - start), travel), angle - start)
        command = self._open_loop(ramped, drive_speed)
        self._goal_error = abs(angle - obs.swivel)
        return command

    def _hold(self, obs: Observation, angle: float, drive_speed: float) -> Command:
        """
        Bring the measured swivel to ``angle`` while driving at ``drive_speed``.

        This is the outer loop (see the module docstring).

        The bias integrates only once the controller's rate-limited set point has reached the
        last command: while it still ramps, the error is the ramp's, not the load's.
        """
        config = self._config
        error = angle - obs.swivel
        dt = obs.time - self._last.time if self._last is not None else 0.0
        if abs(obs.set_point - self._last_command) < config.swivel_tolerance:
            self._bias = min(config.max_bias, max(
                -config.max_bias, self._bias + config.bias_gain * error * dt))
        self._goal_error = abs(error)
        limit = self._p.swivel_limit
        self._last_command = min(limit, max(-limit, angle + self._bias))
        return Command(self._last_command, config.swivel_rate, drive_speed, True)

    def _settled(self, obs: Observation, target: float) -> bool:
        """Tell whether the swivel is at ``target`` and at rest for ``settle_time``."""
        config = self._config
        if (abs(obs.swivel - target) <= config.swivel_tolerance
                and abs(obs.swivel_rate) <= config.settle_rate):
            if self._at_rest_since is None:
                self._at_rest_since = obs.time
            return obs.time - self._at_rest_since >= config.settle_time
        self._at_rest_since = None
        return False

    def _enter(self, step: Step, obs: Observation) -> Command:
        """Switch to ``step`` and return its first command."""
        self._switch(step, obs)
        return self._advance(obs)

    def _switch(self, step: Step, obs: Observation) -> None:
        self._step = step
        self._progress_ref = (obs.time, self._path)
        self._at_rest_since = None
        self._stall_ref = (obs.time, math.inf)
        limit = self._p.swivel_limit
        self._ramp_start = (obs.time, min(limit, max(-limit, obs.swivel)))
        plan, config = self._plan, self._config
        spans = {
            Step.STOP: (abs(obs.speed), 0.0),
            Step.BACK_UP: (self._backed_up(obs), plan.backup_distance),
            Step.APPROACH: (self._lifted_wheel_distance(obs), -plan.lead_distance),
            Step.PRESS: (self._lifted_wheel_distance(obs),
                         -(plan.lead_distance - self._config.lift_gap)),
            Step.LIFT: (obs.swivel, plan.swivel_angle),
            Step.ADVANCE: (self._advance_distance(obs), self._advance_goal()),
            Step.SET_DOWN: (obs.swivel, plan.second_swivel_angle),
            Step.SECOND_ADVANCE: (self._second_wheel_distance(obs), config.lead_margin),
            Step.SECOND_SET_DOWN: (obs.swivel, 0.0),
            Step.REAR: (self._rear_wheel_distance(obs), config.rest_margin),
            Step.STOP_ON_TOP: (abs(obs.speed), 0.0)}
        self._span = spans.get(step, (0.0, 1.0))
        self._slip_ref = wrap_angle(self._heading(obs) - obs.yaw)

    # --- geometry -------------------------------------------------------------------------

    def _wheel_distance(self, obs: Observation, bx: float, by: float) -> float:
        """
        Signed distance past the edge of a wheel's contact given at rest in base_link.

        The rest geometry ignores how the swivel moves the front contacts (a few cm at the
        lift angles); ``lead_margin`` and ``lift_gap`` absorb it.
        """
        pose = Pose2D(obs.x, obs.y, self._heading(obs))
        return self._edge.signed_distance(*pose.transform(bx, by))

    def _heading(self, obs: Observation) -> float:
        """Return the car's heading in the odometry frame from the IMU (module docstring) [rad]."""
        return wrap_angle(obs.imu_yaw - self._yaw_offset)

    def _lifted_wheel_distance(self, obs: Observation) -> float:
        return self._wheel_distance(obs, self._p.wheelbase, self._plan.lifted_side * self._p.h)

    def _advance_distance(self, obs: Observation) -> float:
        """
        Return what ADVANCE drives until it reaches ``_advance_goal`` [m].

        The lifted wheel's rest contact past the edge, or for a push-lift the point where it
        will land.
        """
        if self._plan.push_lift:
            return self._wheel_distance(obs, *self._plan.lifted_point)
        return self._lifted_wheel_distance(obs)

    def _advance_goal(self) -> float:
        """Return the goal of ``_advance_distance`` [m]."""
        config = self._config
        return config.push_margin if self._plan.push_lift else config.lead_margin

    def _second_wheel_distance(self, obs: Observation) -> float:
        return self._wheel_distance(obs, self._p.wheelbase, -self._plan.lifted_side * self._p.h)

    def _rear_wheel_distance(self, obs: Observation) -> float:
        """Return the distance past the edge of the rear wheel nearer the riser (trailing) [m]."""
        return min(self._wheel_distance(obs, 0.0, self._p.h),
                   self._wheel_distance(obs, 0.0, -self._p.h))

    def _progress_quantity(self, obs: Observation) -> float:
        if self._step in (Step.STOP, Step.STOP_ON_TOP):
            return abs(obs.speed)
        if self._step == Step.BACK_UP:
            return self._backed_up(obs)
        if self._step in (Step.APPROACH, Step.PRESS):
            return self._lifted_wheel_distance(obs)
        if self._step == Step.ADVANCE:
            return self._advance_distance(obs)
        if self._step == Step.SECOND_ADVANCE:
            return self._second_wheel_distance(obs)
        if self._step == Step.REAR:
            return self._rear_wheel_distance(obs)
        return obs.swivel

    # --- monitors and bookkeeping ---------------------------------------------------------

    def _start(self, obs: Observation) -> None:
        self._origin = Pose2D(obs.x, obs.y, obs.yaw)
        self._edge = StepEdge.from_request(self._origin, self._p.wheelbase,
                                           self._step_distance, self._step_yaw)
        self._start_time = obs.time
        self._yaw_offset = obs.imu_yaw - obs.yaw
        moving = abs(obs.speed) > self._config.stop_speed
        if moving:
            self._last_command = obs.swivel
        self._switch(Step.STOP if moving else self._first_move(), obs)

    def _measure(self, obs: Observation) -> None:
        if self._last is not None:
            dt = max(0.0, obs.time - self._last.time)
            self._path += math.hypot(obs.x - self._last.x, obs.y - self._last.y)
            self._energy += abs(obs.torque * obs.swivel_rate) * dt
        self._peak_torque = max(self._peak_torque, abs(obs.torque))
        self._max_pitch = max(self._max_pitch, abs(obs.pitch))

    def _monitor(self, obs: Observation) -> tuple[ErrorCode, str] | None:
        config = self._config
        name = self._step.name
        if self._cancel_requested:
            return ErrorCode.CANCELED, 'canceled: drive stopped, swivel held'
        if obs.time - self._start_time > self._allowance:
            return ErrorCode.TIMEOUT, f'timed out after {self._allowance:.1f} s in {name}'
        margin = float(kinematics.tip_over_margin(self._p, max(0.0, -obs.pitch)))
        if margin < config.pitch_abort_margin:
            return (ErrorCode.TIP_OVER_ABORT,
                    f'nose-up pitch {-obs.pitch:.3f} rad is {margin:.3f} rad from tipping '
                    f'over (abort margin {config.pitch_abort_margin:.3f} rad) in {name}')
        # Stall: for stall_time the swivel closes less than stall_progress on the angle the
        # step wants. Not while steering: a lagging steering angle is no hazard, and the
        # no-progress monitor covers a car that does not move.
        ref_time, best = self._stall_ref
        error = self._goal_error
        if error is None or error <= config.swivel_tolerance \
                or error < best - config.stall_progress:
            self._stall_ref = (obs.time, math.inf if error is None else error)
        elif obs.time - ref_time > config.stall_time:
            return (ErrorCode.STALL,
                    f'the swivel made no headway for {config.stall_time:.1f} s in {name} '
                    f'({error:.3f} rad off)')
        slip = wrap_angle(self._heading(obs) - obs.yaw - self._slip_ref)
        if self._step == Step.REAR and abs(slip) > config.slip_yaw_tolerance:
            return (ErrorCode.NO_PROGRESS,
                    f'the wheels slip: the IMU heading has turned {slip:+.2f} rad away from '
                    f"the odometry's in {name}")
        if self._step in _DRIVING:
            ref_time, ref_path = self._progress_ref
            if self._path - ref_path >= config.min_progress:
                self._progress_ref = (obs.time, self._path)
            elif obs.time - ref_time > config.no_progress_time:
                return (ErrorCode.NO_PROGRESS,
                        f'moved less than {config.min_progress:.3f} m in '
                        f'{config.no_progress_time:.1f} s in {name}')
        return None

    def _progress(self, obs: Observation) -> float:
        if self._step == Step.DONE:
            return 1.0
        start = self._step.progress_start
        end = _STEPS[_STEPS.index(self._step) + 1].progress_start
        first, last = self._span
        span = last - first
        fraction = (self._progress_quantity(obs) - first) / span if abs(span) > 1e-9 else 1.0
        return start + (end - start) * min(1.0, max(0.0, fraction))

    def _publish_feedback(self, obs: Observation) -> None:
        failed = self.outcome is not None and not self.outcome.success
        phase = Phase.ABORTING if failed else self._step.phase
        self.feedback = Feedback(
            phase, phase.name if failed or phase != Phase.CLIMB_REST
            else f'{phase.name}: {self._step.name}',
            self.feedback.progress if failed else self._progress(obs),
            obs.pitch, obs.roll, obs.swivel, obs.torque,
            -self._wheel_distance(obs, self._p.wheelbase, 0.0))

    def _finish(self, obs: Observation, code: ErrorCode, message: str) -> Command:
        if code == ErrorCode.NONE:
            self._step = Step.DONE
        self.outcome = Outcome(
            code == ErrorCode.NONE, code, message, obs.time - self._start_time,
            self._peak_torque, self._energy, self._max_pitch, self._path)
        self._hold_angle = obs.swivel
        self._publish_feedback(obs)
        return self._final_command()

    def _final_command(self) -> Command:
        """After success the swivel goes back to cmd_vel; after a failure it holds."""
        if self.outcome.success:
            return Command(0.0, 0.0, 0.0, False)
        return Command(self._hold_angle, 0.0, 0.0, True)
