"""
The lockstep protocol (docs/architecture.md, "Timing: sim time and lockstep"), ROS-free.

One owner for the chain's timing: ``SimLockstep`` decides when the sim advances,
``ChainedAnswers`` when the controller answers a state, ``ChainEntry`` when a source that
joins the chain (the planner, a driver) may act on the states it hears. Stamps are integer
nanoseconds of sim time (0: none); the wall clock is the caller's (``now_ns``, a steady clock
in ns, passed to every call), so the protocol runs the same under a fake clock in tests.
"""

from __future__ import annotations

from dataclasses import dataclass
import enum
from typing import Any, Generic, NamedTuple, TypeVar

T = TypeVar('T')

# While it waits for a command the sim publishes its state again, so that a controller
# started after it (or a lost message) still gets the state it must answer.
REPUBLISH_PERIOD_NS = 100_000_000  # [ns] wall
# Longest period of the sim's lockstep timer.
SIM_TICK_NS = 20_000_000  # [ns] wall


def stamp_ns(stamp) -> int:
    """Return a stamp (anything with integer ``sec`` and ``nanosec``) in ns [ns]."""
    return stamp.sec * 1_000_000_000 + stamp.nanosec


class SimTick(NamedTuple):
    """What the sim does on a tick of its lockstep timer."""

    periods: int  # control periods to advance now
    republish: bool  # publish the current state again
    timed_out: bool  # lockstep_timeout passed: real time from now on, until a command comes


_WAIT = SimTick(0, False, False)
_REPUBLISH = SimTick(0, True, False)
_ADVANCE = SimTick(1, False, False)
_TIME_OUT = SimTick(1, False, True)


class SimLockstep:
    """
    The sim's side: after publishing the state of sim time t, wait for the command stamped t.

    The sim calls ``published``, ``advanced``, ``stepped`` and ``reset`` as it moves, asks
    ``accepts`` and ``heard`` for each command and ``tick`` on its timer; they answer when it
    advances. With no command for ``timeout_ns`` the controller is taken for gone and the sim
    runs at real time (its actuator watchdog stopping the car) until any command comes, then
    waits again. ``real_time_factor`` caps the pace (0: none) for nodes outside the chain.
    It also holds the pause, which a free-running sim obeys too, and ``run_for``: a number of
    control periods, then the pause, at the state they end in whatever the machine's speed.

    Parameters
    ----------
    control_period_ns : int
        Sim time one advance takes, > 0. # [ns]
    timeout_ns : int
        Wall time to wait for a command, 0: forever. # [ns]
    real_time_factor : float
        At most this much sim time per wall time, 0: no cap. # [1]
    paused : bool
        Start paused.
    now_ns : int
        Steady wall clock now. # [ns]

    """

    def __init__(self, control_period_ns: int, timeout_ns: int, real_time_factor: float,
                 paused: bool, now_ns: int) -> None:
        self.control_period_ns = control_period_ns
        self.timeout_ns = timeout_ns
        # Wall time an advance must at least take.
        self.min_period_ns = (round(control_period_ns / real_time_factor)
                              if real_time_factor > 0.0 else 0)  # [ns]
        self.paused = paused
        self.pause_at_ns: int | None = None  # [ns] sim time of the state to pause at
        self.sim_ns = 0  # [ns] sim time of the state a command must answer
        self.reset_ns = 0  # [ns] sim time of the first state after the last reset
        self.command_ready = False  # the command of sim_ns came and is applied
        self.unanswered = False  # timed out: real time until a command comes
        self._period_start = now_ns  # [ns] wall, of the last advance (or pause, reset)
        self._last_publish = now_ns  # [ns] wall
        self._next_due = now_ns  # [ns] wall, earliest next advance under the pace cap

    @property
    def tick_period_ns(self) -> int:
        """Period of the timer that calls ``tick``: fine enough for the timeout and cap."""
        period = (SIM_TICK_NS if self.timeout_ns == 0
                  else min(SIM_TICK_NS, self.timeout_ns // 4))  # [ns]
        if self.min_period_ns > 0:
            period = min(period, self.min_period_ns // 2)
        return period

    def published(self, stamp_ns: int, now_ns: int) -> None:
        """Note that the state of ``stamp_ns`` [ns] was published at ``now_ns`` [ns]."""
        self.sim_ns = stamp_ns
        self._last_publish = now_ns

    def advanced(self, stamp_ns: int, now_ns: int) -> None:
        """Note an advance of one control period, its state of ``stamp_ns`` [ns] published."""
        self.command_ready = False
        self._period_start = now_ns
        # An absolute schedule, so the timer's lag does not add up period by period (it did:
        # 0.67x at a pace of 1x); a sim behind it restarts it, never ahead.
        due = self._next_due + self.min_period_ns
        self._next_due = due if due >= now_ns else now_ns + self.min_period_ns
        self.published(stamp_ns, now_ns)
        if self.pause_at_ns is not None and stamp_ns >= self.pause_at_ns:
            self.paused = True
            self.pause_at_ns = None

    def stepped(self, stamp_ns: int) -> None:
        """Note a ``~/step`` call that moved the sim to ``stamp_ns`` [ns], the time to answer."""
        self.command_ready = False
        self.sim_ns = stamp_ns

    def reset(self, stamp_ns: int, now_ns: int) -> None:
        """
        Note a reset of the world, its first state, of ``stamp_ns`` [ns], published.

        Commands stamped before it answer the old world: ``accepts`` refuses them.
        """
        self.command_ready = False
        self.reset_ns = stamp_ns
        self._period_start = now_ns
        self.published(stamp_ns, now_ns)

    def set_paused(self, paused: bool, now_ns: int) -> bool:
        """
        Pause or resume (ending a ``run_for``); the timeout restarts.

        Return whether to advance now.
        """
        self.paused = paused
        self.pause_at_ns = None
        self._period_start = now_ns
        return not paused and self.command_ready

    def run_for(self, periods: int, now_ns: int) -> bool:
        """
        Resume for ``periods`` (>= 1) control periods, then pause at the state they end in.

        Return whether to advance now. The sim time to pause at is ``pause_at_ns``.
        """
        if periods < 1:
            raise ValueError(f'periods must be >= 1, got {periods}')
        advance = self.set_paused(False, now_ns)
        self.pause_at_ns = self.sim_ns + periods * self.control_period_ns
        return advance

    def accepts(self, stamp_ns: int) -> bool:
        """Tell whether a command stamped ``stamp_ns`` [ns] (0: unstamped) may be applied."""
        return not 0 < stamp_ns < self.reset_ns

    def heard(self, stamp_ns: int, now_ns: int) -> bool:
        """
        Take a command stamped ``stamp_ns`` [ns] that the sim applied.

        Any command brings back the waiting; the one of the current state makes it ready.
        Return whether to advance now (not paused, and the pace cap allows).
        """
        self.unanswered = False
        if stamp_ns != self.sim_ns:
            return False
        self.command_ready = True
        return not self.paused and now_ns >= self._next_due

    def tick(self, now_ns: int) -> SimTick:
        """Return what to do at ``now_ns`` [ns], on the lockstep timer."""
        if self.paused:
            return _WAIT
        if self.command_ready:
            return _ADVANCE if now_ns >= self._next_due else _WAIT
        since = now_ns - self._period_start  # [ns]
        if self.unanswered:
            # The periods due since the last advance: real time on average, whatever the
            # timer's period.
            return SimTick(since // self.control_period_ns, False, False)
        if 0 < self.timeout_ns < since:
            self.unanswered = True
            return _TIME_OUT
        if now_ns - self._last_publish > REPUBLISH_PERIOD_NS:
            return _REPUBLISH
        return _WAIT


@dataclass
class ChainedSource:
    """A command stream the controller waits for in lockstep (docs/architecture.md)."""

    name: str  # its topic
    enabled: bool  # the lockstep_* parameter
    heard_ns: int = 0  # [ns] stamp of its last stamped command (0: none)
    # That stamp as the caller gave it (its message, which a controller state reports without
    # building one), None with heard_ns 0.
    heard_stamp: Any = None
    chained: bool = False  # the command in force came stamped: it takes part in the chain
    late: bool = False  # missed a wait: not waited for until its next stamped command

    def hear(self, stamp_ns: int, applied: bool, stamp: Any = None) -> None:
        """
        Take a command stamped ``stamp_ns`` [ns] (0: unstamped), ``stamp`` in the caller's form.

        A stamped one answers its cycle, refused or not; an ``applied`` one puts the source in
        the chain when stamped, out of it when not.
        """
        if stamp_ns:
            self.heard_ns, self.heard_stamp, self.late = stamp_ns, stamp, False
        if applied:
            self.chained = stamp_ns != 0

    def awaited(self, last_ns: int) -> bool:
        """Tell whether its answer to the state of ``last_ns`` [ns] is still to come."""
        return self.enabled and self.chained and not self.late and last_ns > self.heard_ns

    def forget(self) -> None:
        """Drop what was heard: a sim reset's new world."""
        self.heard_ns, self.heard_stamp, self.chained = 0, None, False


class ChainedAnswers(Generic[T]):
    """
    The controller's side: answer a state once the chained sources answered the one before.

    A source (``planner``: the stamped ``swivel_command``, while one is held; ``driver``: a
    stamped ``cmd_vel``) is in the chain from its stamped command on. A state waits (pending,
    kept as the caller's ``T``) until each such source has answered the last state answered,
    or for at most ``wait_ns`` of wall time; then the sources that did not are late and not
    waited for until their next stamped command.

    Parameters
    ----------
    wait_ns : int
        Longest wall-time wait for a source, > 0. # [ns]
    swivel_command, cmd_vel : bool
        Whether the planner and the driver may join the chain.

    """

    def __init__(self, wait_ns: int, swivel_command: bool, cmd_vel: bool) -> None:
        self.wait_ns = wait_ns
        self.planner = ChainedSource('swivel_command', swivel_command)
        self.driver = ChainedSource('cmd_vel', cmd_vel)
        self.last_ns: int | None = None  # [ns] stamp of the last state answered in full
        self._pending: T | None = None
        self._pending_ns = 0  # [ns] its stamp
        self._pending_since = 0  # [ns] wall

    def awaited(self, stamp_ns: int, holding: bool) -> list[ChainedSource]:
        """
        List the sources whose commands the state of ``stamp_ns`` [ns] waits for.

        Their answers to the last state answered; the planner's only while its command is
        ``holding`` (released or timed out: nothing to wait for).
        """
        last_ns = self.last_ns
        if last_ns is None or stamp_ns <= last_ns:
            return []
        sources = [self.planner, self.driver] if holding else [self.driver]
        return [source for source in sources if source.awaited(last_ns)]

    def state(self, stamp_ns: int, item: T, holding: bool, now_ns: int) -> T | None:
        """
        Take the state ``item`` of ``stamp_ns`` [ns]; return it to be answered now, or None.

        None: it is pending (an earlier pending state is dropped). ``holding``: a
        swivel_command is held; ``now_ns`` [ns] wall.
        """
        if self.awaited(stamp_ns, holding):
            if self._pending is None or self._pending_ns != stamp_ns:
                self._pending_since = now_ns
            self._pending, self._pending_ns = item, stamp_ns
            return None
        self._pending = None
        return item

    def heard(self, source: ChainedSource, stamp_ns: int, applied: bool, holding: bool,
              stamp: Any = None) -> T | None:
        """
        Take a command of ``source``; return the pending state if it is to be answered now.

        See ``ChainedSource.hear``; ``holding``: a swivel_command is held after the command.
        """
        source.hear(stamp_ns, applied, stamp)
        if self._pending is not None and not self.awaited(self._pending_ns, holding):
            return self._take()
        return None

    def tick(self, holding: bool, now_ns: int) -> tuple[T | None, list[ChainedSource]]:
        """
        Return the pending state once it waited ``wait_ns``, with the sources late for it.

        Those are marked late. ``(None, [])`` while nothing is to be answered.
        """
        if self._pending is None or now_ns - self._pending_since <= self.wait_ns:
            return None, []
        late = self.awaited(self._pending_ns, holding)
        for source in late:
            source.late = True
        return self._take(), late

    def answered(self, stamp_ns: int) -> None:
        """
        Note that the state of ``stamp_ns`` [ns] was answered in full (command and state).

        One before the last answered is a restarted sim's new world (its clock from 0): the
        sources' commands were the old world's, forgotten as at a reset. Kept, a driver's
        stamp of the old world would be reported as its answer in the new one, and waited for
        again once the new world's clock passed it.
        """
        if self.last_ns is not None and stamp_ns < self.last_ns:
            self.planner.forget()
            self.driver.forget()
        self.last_ns = stamp_ns

    def repeats(self, stamp_ns: int) -> bool:
        """
        Tell whether the state of ``stamp_ns`` [ns] is the one last answered in full.

        The lockstep sim publishes a state again until its answer comes (every
        ``REPUBLISH_PERIOD_NS`` of wall time): a copy that crossed the answer gets the same
        command again, and nothing else. Answered anew, with a planner's command for the next
        state come meanwhile, it would give another controller state of that moment, which
        the planner may tick on, and the run would depend on the machine's load.
        """
        return stamp_ns == self.last_ns

    def forget(self, reset_ns: int) -> None:
        """Forget the old world's pending state and commands: a sim reset at ``reset_ns``."""
        if self._pending is not None and self._pending_ns < reset_ns:
            self._pending = None
        self.planner.forget()
        self.driver.forget()

    def _take(self) -> T | None:
        item, self._pending = self._pending, None
        return item


class Entry(enum.Enum):
    """What a source joining the chain does with a state (``ChainEntry.state``)."""

    FIRST = 'first'  # send its first command, answering this state
    REPEAT = 'repeat'  # send its first command again, answering this state
    ENGAGED = 'engaged'  # the controller holds the first command: go on from it
    ENGAGED_LATE = 'engaged late'  # as ENGAGED, but states passed meanwhile: start afresh here
    ON = 'on'  # engaged before: act on this state


class ChainEntry:
    """
    A source's way into the lockstep chain (docs/architecture.md).

    The controller waits for a source only from its first stamped command on, so until the
    controller reports hearing that command the sim may run ahead of the source by any time.
    The first command then stands for each state the source hears; once the controller
    reports it, the source goes on, from the state it answers then if states passed
    meanwhile. Stamps of one clock in one unit (the chain's ns, or seconds), compared only
    with each other; a controller that heard none reports one below any state's.
    """

    def __init__(self) -> None:
        self.first: float | None = None  # stamp of the state the first command answered
        self.engaged = False
        self._waited = False  # a state passed between the first command and the engagement

    def state(self, stamp: float, heard: float) -> Entry:
        """
        Take a state of ``stamp`` whose controller reports ``heard``: its last command heard.

        Returns what the source does with that state.
        """
        if self.engaged:
            return Entry.ON
        if self.first is None:
            self.first = stamp
            return Entry.FIRST
        if heard < self.first:
            self._waited = True
            return Entry.REPEAT
        self.engaged = True
        return Entry.ENGAGED_LATE if self._waited else Entry.ENGAGED
