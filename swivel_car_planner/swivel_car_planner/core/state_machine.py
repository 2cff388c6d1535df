"""
The climb as a state machine: one observation in per control cycle, one swivel command out.

The steps and what each one does are the classes of ``steps`` (``BEHAVIOURS``); this class
enters them, and every cycle first watches what ends any step: the time allowance (TIMEOUT),
nose-up pitch near the tip-over rule (TIP_OVER_ABORT), the swivel not closing on a wanted angle
(STALL), no path length while driving (NO_PROGRESS) and the step's own ``watch``. Any failure
stops the drive and holds the swivel where it is.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

from swivel_car_model import kinematics
from swivel_car_model.params import SwivelCarParams

from swivel_car_planner.core import steps
from swivel_car_planner.core.codes import ErrorCode, Phase
from swivel_car_planner.core.config import PlannerConfig
from swivel_car_planner.core.plan import ClimbPlan
from swivel_car_planner.core.reposition import reposition_time
from swivel_car_planner.core.steps import Climb, Command, Finish, Observation, Step

__all__ = ['ClimbStateMachine', 'Command', 'Feedback', 'Observation', 'Outcome', 'Step']

_STEPS = list(Step)
# Steps the feedback names beside their phase: the climb's rest, and the path to the approach.
_NAMED = {Step.REPOSITION} | {step for step in Step if step.phase == Phase.CLIMB_REST}


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
        self._step_distance = step_distance
        self._step_yaw = step_yaw
        # The default allowance is the climb's: a repositioning path gets its time on top.
        self._allowance = time_allowance if time_allowance > 0.0 else (
            config.time_allowance + reposition_time(p, config, plan.reposition))
        self._step = Step.APPROACH
        self._climb: Climb | None = None  # from the first observation on
        self._behaviour: steps.StepBehaviour | None = None  # the step running
        self._start_time = 0.0  # [s]
        self._path = 0.0  # [m]
        self._peak_torque = 0.0  # [N m]
        self._energy = 0.0  # [J]
        self._max_pitch = 0.0  # [rad]
        self._progress_ref = (0.0, 0.0)  # (time [s], path [m]) of the last progress
        self._stall_ref = (0.0, math.inf)  # (time [s], best error [rad]) of the last headway
        self._cancel_requested = False
        self._hold_angle = 0.0  # [rad] swivel held after a failure
        self.outcome: Outcome | None = None
        self.feedback = Feedback(Phase.PLANNING, 'PLANNING', 0.0, 0.0, 0.0, 0.0, 0.0,
                                 step_distance)

    @property
    def phase(self) -> Phase:
        return self._step.phase

    @property
    def step(self) -> Step:
        return self._step

    @property
    def climb(self) -> Climb | None:
        """Return what the steps share: the edge, the car on it (None before an observation)."""
        return self._climb

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
        if self._climb is None or self._climb.last is None:
            self.outcome = Outcome(False, code, message, 0.0, 0.0, 0.0, 0.0, 0.0)
            return None
        return self._finish(self._climb.last, code, message)

    def update(self, obs: Observation) -> Command:
        """Advance the climb by one observation; returns the command to send now."""
        if self.outcome is not None:
            return self._final_command()
        if self._climb is None:
            self._start(obs)
        self._measure(obs)
        failure = self._monitor(obs)
        if failure is not None:
            return self._finish(obs, failure.code, failure.message)
        command = self._advance(obs)
        self._climb.last = obs
        if self.outcome is not None:
            return self._final_command()
        self._publish_feedback(obs)
        return command

    def _advance(self, obs: Observation) -> Command:
        """Run the step; a step it enters runs in the same cycle."""
        while True:
            result = self._behaviour.update(obs)
            if isinstance(result, Step):
                self._switch(result, obs)
            elif isinstance(result, Finish):
                return self._finish(obs, result.code, result.message)
            else:
                return result

    def _switch(self, step: Step, obs: Observation) -> None:
        self._behaviour = steps.enter(step, self._climb, obs)
        self._step = step
        self._progress_ref = (obs.time, self._path)
        self._stall_ref = (obs.time, math.inf)

    def _start(self, obs: Observation) -> None:
        self._climb = Climb(self._p, self._config, self._plan, obs, self._step_distance,
                            self._step_yaw)
        self._start_time = obs.time
        self._switch(steps.first_step(self._climb, obs), obs)

    # --- monitors and bookkeeping ---------------------------------------------------------

    def _measure(self, obs: Observation) -> None:
        last = self._climb.last
        if last is not None:
            dt = max(0.0, obs.time - last.time)
            self._path += math.hypot(obs.x - last.x, obs.y - last.y)
            self._energy += abs(obs.torque * obs.swivel_rate) * dt
        self._peak_torque = max(self._peak_torque, abs(obs.torque))
        self._max_pitch = max(self._max_pitch, abs(obs.pitch))

    def _monitor(self, obs: Observation) -> Finish | None:
        config = self._config
        name = self._step.name
        if self._cancel_requested:
            return Finish(ErrorCode.CANCELED, 'canceled: drive stopped, swivel held')
        if obs.time - self._start_time > self._allowance:
            return Finish(ErrorCode.TIMEOUT, f'timed out after {self._allowance:.1f} s in {name}')
        margin = float(kinematics.tip_over_margin(self._p, max(0.0, -obs.pitch)))
        if margin < config.pitch_abort_margin:
            return Finish(ErrorCode.TIP_OVER_ABORT,
                          f'nose-up pitch {-obs.pitch:.3f} rad is {margin:.3f} rad from '
                          f'tipping over (abort margin {config.pitch_abort_margin:.3f} rad) in '
                          f'{name}')
        # Stall: for stall_time the swivel closes less than stall_progress on the angle the
        # step wants. Not while steering: a lagging steering angle is no hazard, and the
        # no-progress monitor covers a car that does not move.
        ref_time, best = self._stall_ref
        error = self._climb.goal_error
        if error is None or error <= config.swivel_tolerance \
                or error < best - config.stall_progress:
            self._stall_ref = (obs.time, math.inf if error is None else error)
        elif obs.time - ref_time > config.stall_time:
            return Finish(ErrorCode.STALL,
                          f'the swivel made no headway for {config.stall_time:.1f} s in {name} '
                          f'({error:.3f} rad off)')
        failure = self._behaviour.watch(obs)
        if failure is not None:
            return failure
        if self._behaviour.driving:
            ref_time, ref_path = self._progress_ref
            if self._path - ref_path >= config.min_progress:
                self._progress_ref = (obs.time, self._path)
            elif obs.time - ref_time > config.no_progress_time:
                return Finish(ErrorCode.NO_PROGRESS,
                              f'moved less than {config.min_progress:.3f} m in '
                              f'{config.no_progress_time:.1f} s in {name}')
        return None

    def _progress(self, obs: Observation) -> float:
        if self._step == Step.DONE:
            return 1.0
        start = self._step.progress_start
        end = _STEPS[_STEPS.index(self._step) + 1].progress_start
        first, last = self._behaviour.span
        span = last - first
        fraction = (self._behaviour.quantity(obs) - first) / span if abs(span) > 1e-9 else 1.0
        return start + (end - start) * min(1.0, max(0.0, fraction))

    def _publish_feedback(self, obs: Observation) -> None:
        failed = self.outcome is not None and not self.outcome.success
        phase = Phase.ABORTING if failed else self._step.phase
        self.feedback = Feedback(
            phase, phase.name if failed or self._step not in _NAMED
            else f'{phase.name}: {self._step.name}',
            self.feedback.progress if failed else self._progress(obs),
            obs.pitch, obs.roll, obs.swivel, obs.torque,
            -self._climb.wheel_distance(obs, self._p.wheelbase, 0.0))

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
