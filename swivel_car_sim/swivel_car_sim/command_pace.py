"""
Free running on sim time, paced by the controller: no step with a command older than a bound.

A free-running sim steps as fast as ``real_time_factor`` allows, a controller answers its
states at the speed of the machine. Without a bound the sim runs ahead (at real_time_factor 0
about 20x) and applies each command long after the state it answers, the swivel loop closed
over a delay of up to the watchdog time: the car spun and swung from side to side. gazebo at
its full speed keeps ros2_control's loop closed by running the controller inside its update;
here the controller is a node of its own, so the sim waits for it instead, as lockstep does,
but pipelined: it may run ``max_age_ns`` of sim time ahead of the newest command. ROS-free;
the wall clock is the caller's (``now_ns``).
"""

from __future__ import annotations


class CommandPace:
    """
    Whether a free-running sim on sim time may step on: its controller's latest command is recent.

    The sim at the state of sim time t steps on only while it holds a command answering a
    state at most ``max_age_ns`` before t (so a command is at most ``max_age_ns`` plus one
    control period old while it is applied). A sim that has heard no stamped command yet runs
    free (nothing drives it, or a driver that does not stamp); one that heard none for
    ``timeout_ns`` of wall time takes the controller for gone and runs free until the next one
    (its actuator watchdog stops the car meanwhile).

    Parameters
    ----------
    max_age_ns : int
        Largest age of the newest command at a state the sim steps on from, >= 0. # [ns] sim
    timeout_ns : int
        Wall time to wait for a command, 0: forever. # [ns]
    now_ns : int
        Steady wall clock now. # [ns]

    """

    def __init__(self, max_age_ns: int, timeout_ns: int, now_ns: int) -> None:
        if max_age_ns < 0 or timeout_ns < 0:
            raise ValueError(f'max_age_ns and timeout_ns must be >= 0, got {max_age_ns}, '
                             f'{timeout_ns}')
        self.max_age_ns = max_age_ns
        self.timeout_ns = timeout_ns
        self.newest_ns = 0  # [ns] sim time of the state the newest command answers, 0: none
        self._heard_at = now_ns  # [ns] wall, of the last command (or start, resume)
        self.timed_out = False  # no command for timeout_ns: free until one comes

    def stale(self, stamp_ns: int, sim_ns: int) -> bool:
        """Tell whether a command stamped ``stamp_ns`` [ns] is too old at sim time ``sim_ns``."""
        return sim_ns - stamp_ns > self.max_age_ns

    def heard(self, stamp_ns: int, now_ns: int) -> None:
        """Take a command stamped ``stamp_ns`` [ns] (stale or not: the controller is there)."""
        self.newest_ns = max(self.newest_ns, stamp_ns)
        self._heard_at = now_ns
        self.timed_out = False

    def restart(self, now_ns: int) -> None:
        """Count the wait for a command from now: the sim moves again (resumed)."""
        self._heard_at = now_ns

    def may_step(self, sim_ns: int, now_ns: int) -> bool:
        """
        Tell whether the sim at the state of ``sim_ns`` [ns] may step on at ``now_ns`` [ns].

        Sets ``timed_out`` when the wait for a command ends here.
        """
        if self.newest_ns == 0 or self.timed_out or not self.stale(self.newest_ns, sim_ns):
            return True
        if 0 < self.timeout_ns < now_ns - self._heard_at:
            self.timed_out = True
            return True
        return False
