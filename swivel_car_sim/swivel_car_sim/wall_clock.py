"""
The sim's hardware clock (``clock_source:=wall``): stamps from the system clock, real-time pace.

ROS-free. A driver board samples at a fixed cadence and stamps each sample with the system
clock. The sim does the same: a state's stamp is its sim time plus an offset to the system
clock, fixed while the sim runs, so that stamps advance exactly as the physics does (the
odometry integrates rates over stamp differences). The pace follows the system clock: each
timer call advances the periods that are due, so a timer that fires late catches up; a sim
more than ``MAX_LAG`` behind (a stalled machine) gives that backlog up instead of racing
through it, and its stamps jump forward by it, as a board's would after a stall.
"""

from __future__ import annotations

MAX_LAG_NS = 100_000_000  # [ns] backlog the sim catches up; beyond it, it skips ahead


class WallPacer:
    """
    Stamps and pace of a free-running sim on the system clock.

    Parameters
    ----------
    control_period_ns : int
        Sim time one advance takes, > 0. # [ns]
    sim_ns : int
        Sim time now. # [ns]
    now_ns : int
        System clock now. # [ns]

    """

    def __init__(self, control_period_ns: int, sim_ns: int, now_ns: int) -> None:
        self.control_period_ns = control_period_ns
        self.offset_ns = now_ns - sim_ns  # [ns] system clock minus sim time
        self.skipped_ns = 0  # [ns] backlog given up in all

    def stamp_ns(self, sim_ns: int) -> int:
        """Return the stamp [ns] of the state of sim time ``sim_ns`` [ns]."""
        return sim_ns + self.offset_ns

    def restart(self, sim_ns: int, now_ns: int) -> None:
        """Start the pace afresh at ``now_ns`` (resumed from a pause, or stepped meanwhile)."""
        self.offset_ns = max(self.offset_ns, now_ns - sim_ns)

    def due(self, sim_ns: int, now_ns: int) -> int:
        """
        Return how many control periods to advance now, at ``now_ns`` [ns] of the system clock.

        A backlog over ``MAX_LAG_NS`` is given up (``skipped_ns``): the stamps jump ahead.
        """
        behind = now_ns - self.stamp_ns(sim_ns)  # [ns]
        if behind > MAX_LAG_NS:
            skip = behind - self.control_period_ns
            self.offset_ns += skip
            self.skipped_ns += skip
            behind -= skip
        return max(0, behind // self.control_period_ns)
