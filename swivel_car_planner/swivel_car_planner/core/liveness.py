"""
When the planner's inputs count as alive, and the one climb slot, ROS-free.

The node asks ``InputLiveness`` whether a request may start a climb, hands it every climb
tick, and asks it on one steady timer whether the running climb has to end. It judges on two
clocks, each where the other is blind: sim time (the node clock) says an input stopped while
the sim runs, wall time says the sim itself stopped (sim time then stands still, and every
input stays fresh by it).
"""

from __future__ import annotations

import math
from typing import Callable, Generic, Iterable, TypeVar

C = TypeVar('C')


class ClimbSlot(Generic[C]):
    """
    The one climb the planner runs at a time, shared by the climb_step service and action.

    A request that moves the robot (not ``plan_only``) takes the slot before its planning
    starts and holds it while its climb runs: meanwhile the service answers another with
    BUSY and the action rejects another goal before accepting it. A planning that ends
    without a climb (a failed plan, a goal canceled, a sim reset while planned) frees it, as
    does the end of the climb. ``plan_only`` requests never take it.
    """

    def __init__(self) -> None:
        self._planning = False
        self.climb: C | None = None  # the running climb

    @property
    def busy(self) -> bool:
        return self._planning or self.climb is not None

    def take(self) -> bool:
        """Take the slot for a planning; False if it is taken."""
        if self.busy:
            return False
        self._planning = True
        return True

    def planned(self, climb: C | None) -> None:
        """End the planning: ``climb`` runs in the slot now, or None frees it."""
        self._planning = False
        self.climb = climb

    def end(self) -> None:
        """Free the slot of its climb."""
        self.climb = None


class InputLiveness:
    """
    The planner's inputs heard on both clocks, and the running climb's ticks.

    Every method takes the node clock's ``sim`` time and a steady ``wall`` time [s].

    Parameters
    ----------
    topics : iterable of str
        Every input.
    ready_timeout : float
        Inputs older than this (in sim and wall time) mean not ready; a climb whose ticks
        stop for this long ends. # [s]

    """

    def __init__(self, topics: Iterable[str], ready_timeout: float) -> None:
        self._topics = tuple(topics)
        self._timeout = ready_timeout
        self._received: dict[str, tuple[float, float]] = {}  # topic -> (sim, wall) heard
        self._clock_last = -math.inf  # [s] sim time at the last input heard
        self._clock_moved_wall = -math.inf  # [s] wall time when an input last saw it move
        self._last_tick = (0.0, 0.0)  # (sim, wall) [s] when the climb last had a tick
        self._last_stamp = -math.inf  # [s] stamp of the climb's last engaged tick
        self._quiet_checks = 0  # checks in a row that saw no tick

    def heard(self, topic: str, sim: float, wall: float) -> None:
        self._received[topic] = (sim, wall)
        if sim != self._clock_last:
            self._clock_last, self._clock_moved_wall = sim, wall

    def clock_stands(self, wall: float) -> bool:
        """Tell whether the inputs have seen sim time stand still for ``ready_timeout``."""
        return wall - self._clock_moved_wall > self._timeout

    def missing(self, sim: float, wall: float, wall_too: bool = False) -> list[str]:
        """
        List the inputs not heard within ``ready_timeout`` of sim time (all, before /clock).

        ``wall_too``: only those not heard within ``ready_timeout`` of wall time either (for a
        request). Out of a climb the planner is outside the lockstep chain and the sim races
        ahead of it: a planner not scheduled for a tenth of a second then takes the newest
        /clock first (its subscription keeps only that one) and the inputs of the same moments
        after it, from their queues, which look a second old in sim time though they came
        milliseconds ago. An input that has stopped is silent on both clocks. A clock that
        stands still (a sim gone, or one restarted but unheard) keeps every input fresh in sim
        time: then wall time alone tells.
        """
        clock_stands = self.clock_stands(wall)

        def silent(topic: str) -> bool:
            heard_sim, heard_wall = self._received[topic]
            return (sim - heard_sim > self._timeout or clock_stands) and \
                (not wall_too or wall - heard_wall > self._timeout)

        return [topic for topic in self._topics
                if sim <= 0.0 or topic not in self._received or silent(topic)]

    def not_ready(self, sim: float, wall: float) -> str | None:
        """Return why a climb may not start now, None if it may."""
        missing = self.missing(sim, wall, wall_too=True)
        if not missing:
            return None
        question = (f'sim time has stood at {sim:.2f} s: is the sim running, not paused?'
                    if self.clock_stands(wall) else
                    'are the sim, controller and odometry running?')
        return f'no recent message on {", ".join(missing)}: {question}'

    def climb_started(self, sim: float, wall: float) -> None:
        self._last_tick = (sim, wall)
        self._last_stamp = -math.inf
        self._quiet_checks = 0

    def tick(self, stamp: float, sim: float, wall: float) -> tuple[float, str] | None:
        """
        Take the climb's tick of ``stamp``; return (stamp, why) to end the climb on it instead.

        Once engaged (``engaged``) consecutive ticks are a control period apart: time going
        back is another world (a restarted sim), a leap is a bad stamp, a clock that jumped or
        a planner the controller gave up waiting for, and acting on it would time out or steer
        on a lie.
        """
        last = self._last_stamp
        if stamp < last:
            return stamp, (f'time went back from {last:.2f} s to {stamp:.2f} s (a restarted '
                           f'sim?): the climb does not go on in another world')
        if math.isfinite(last) and stamp - last > self._timeout:
            return last, (f'the inputs leapt from {last:.2f} s to {stamp:.2f} s, more than '
                          f'ready_timeout ({self._timeout} s): not acted on')
        self._last_tick = (sim, wall)
        self._quiet_checks = 0
        return None

    def engaged(self, stamp: float) -> None:
        """Note that the controller waits for the climb's commands from the tick of ``stamp``."""
        self._last_stamp = stamp

    def check(self, sim: float, wall: float, engaged: bool,
              describe: Callable[[], str]) -> tuple[float, str] | None:
        """
        Return (stamp, why) to end a climb without a tick for ``ready_timeout``, or None.

        Of sim time only once ``engaged`` (before, the sim is not held back for the planner
        and its time may race); of wall time always (a dead or paused sim stops sim time).
        Only after two checks in a row without a tick: after the executor was held up (a
        loaded machine), the check runs before the queued inputs and would see a stale tick.
        ``describe`` adds the inputs' stamps to the reason.
        """
        self._quiet_checks += 1
        if self._quiet_checks < 2:
            return None
        tick_sim, tick_wall = self._last_tick
        if engaged and sim - tick_sim > self._timeout:
            missing = ', '.join(self.missing(sim, wall)) or 'none'
            return sim, (f'no complete input for {sim - tick_sim:.1f} s of sim time at '
                         f'{sim:.2f} s; missing: {missing}; {describe()}')
        if wall - tick_wall > self._timeout:
            return sim, (f'no complete input for {wall - tick_wall:.1f} s of wall time while '
                         f'sim time went from {tick_sim:.2f} s to {sim:.2f} s: is the sim '
                         f'running (not paused)? {describe()}')
        return None
