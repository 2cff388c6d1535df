"""
The sim's hardware clock (``clock_source:=wall``): stamps from the system clock, real-time pace.

ROS-free. A driver board samples at a fixed cadence and stamps each sample with the system
clock. The sim does the same: a state's stamp is its sim time plus an offset to the system
clock, fixed while the sim runs, so that stamps advance exactly as the physics does (the
odometry integrates rates over stamp differences). The pace follows the system clock: each
timer call advances the periods that are due, so a timer that fires late catches up. A
backlog over ``QUIET_LAG_NS`` (a busy machine) is caught up in physics without publishing
its states but the last, as if the link had lost them: the robot goes on moving meanwhile,
as a real one does while its computer stalls, and the next state's rates span the gap. Only
a backlog over ``MAX_LAG_NS`` (a stalled machine) is given up: the stamps jump forward by it
while the physics did not move.
"""

from __future__ import annotations

QUIET_LAG_NS = 50_000_000  # [ns] backlog caught up publishing only its last state
MAX_LAG_NS = 1_000_000_000  # [ns] backlog the sim catches up; beyond it, it skips ahead


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

    def due(self, sim_ns: int, now_ns: int) -> tuple[int, int]:
        """
        Return the control periods to advance now, at ``now_ns`` [ns] of the system clock.

        (quiet, published): the first ``quiet`` periods are stepped without publishing
        their states (a backlog over ``QUIET_LAG_NS``), then ``published`` periods are
        advanced as usual. A backlog over ``MAX_LAG_NS`` is given up (``skipped_ns``): the
        stamps jump ahead.
        """
        behind = now_ns - self.stamp_ns(sim_ns)  # [ns]
        if behind > MAX_LAG_NS:
            skip = behind - self.control_period_ns
            self.offset_ns += skip
            self.skipped_ns += skip
            behind -= skip
        periods = max(0, behind // self.control_period_ns)
        if behind > QUIET_LAG_NS:
            return periods - 1, 1
        return 0, periods
