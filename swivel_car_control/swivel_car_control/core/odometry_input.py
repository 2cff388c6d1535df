"""
Which ``joint_states`` messages the odometry may integrate, ROS-free.

One message with a wild velocity or stamp moved the odometry for good (issue 12: a wheel
rate of 1e300 once, or one stamp of 0 s while driving, put it metres to 1e296 m off). The
gate refuses such a message before it reaches the integrator:

- a reported velocity that is infinite or beyond what the joint can do, a swivel position
  past its stop (``JointStateOdometry.check``);
- a stamp that is not after the last one integrated (a repeat is dropped quietly: the
  lockstep sim republishes a state while it waits);
- a stamp more than ``max_gap`` after the last one.

A jump in time is real (a restarted sim starts again at 0) when the next message follows
the jumped one; then the integration restarts from that next message, the pose kept.
"""

from __future__ import annotations

from dataclasses import dataclass
import enum
import math
from typing import Mapping, Sequence

from swivel_car_control.core.joint_states import ImpossibleReading, JointStateOdometry, MAX_GAP
from swivel_car_model.checks import check_number

# A wheel joint faster than this many times the drive's speed limit is a bad reading: an
# open differential spins one wheel at up to twice the drive speed, skid adds a little.
WHEEL_RATE_FACTOR = 3.0  # [1]


class Verdict(enum.Enum):
    """What to do with one message."""

    INTEGRATE = 'integrate'
    RESTART = 'restart'  # integrate it as the first of a new time base, the pose kept
    REPEAT = 'repeat'  # the same stamp again: nothing to integrate, nothing to say
    REFUSE = 'refuse'


@dataclass(frozen=True)
class Admission:
    """The gate's answer: the verdict and, for REFUSE and RESTART, why."""

    verdict: Verdict
    reason: str = ''


class JointStateGate:
    """
    Admits ``joint_states`` messages to the odometry (see the module docstring).

    Parameters
    ----------
    max_rates : mapping of str to float
        Largest believable |velocity| of each joint the odometry reads, > 0. # [rad/s]
    max_gap : float
        Longest stamp gap integrated across, > 0. # [s]

    """

    def __init__(self, max_rates: Mapping[str, float], max_gap: float = MAX_GAP) -> None:
        self.max_rates = {name: check_number(f'the rate limit of {name!r}', limit, above=0.0,
                                             unit='rad/s')
                          for name, limit in max_rates.items()}
        self.max_gap = check_number('max_gap', max_gap, above=0.0, unit='s')
        self.last_time: float | None = None  # [s] of the last message admitted
        self._jumped_to: float | None = None  # [s] stamp of a refused jump, to confirm

    def admit(self, t: float, names: Sequence[str], velocities: Sequence[float]) -> Admission:
        """
        Decide whether to integrate the message of time ``t`` [s].

        Its ``velocities`` [rad/s] are in the order of ``names`` (an empty or short list, or a
        NaN, is a velocity not reported: the odometry differences positions instead). An
        admitted message becomes the last.
        """
        jumped_to, self._jumped_to = self._jumped_to, None  # only the next message confirms
        if not math.isfinite(t):
            return Admission(Verdict.REFUSE, f'stamp {t!r} s is not finite')
        reason = self._bad_velocity(names, velocities)
        if reason:
            return Admission(Verdict.REFUSE, reason)
        last = self.last_time
        if last is None or last < t <= last + self.max_gap:
            self.last_time = t
            return Admission(Verdict.INTEGRATE)
        if t == last:
            return Admission(Verdict.REPEAT)
        if jumped_to is not None and jumped_to < t <= jumped_to + self.max_gap:
            self.last_time = t
            return Admission(Verdict.RESTART, f'time jumped from {last:.3f} s to '
                                              f'{jumped_to:.3f} s and goes on from there')
        self._jumped_to = t
        direction = 'before' if t < last else 'after'
        return Admission(Verdict.REFUSE, f'stamp {t:.3f} s is {abs(t - last):.3f} s {direction} '
                                         f'the last one ({last:.3f} s): held back until the '
                                         'next message confirms the jump')

    def _bad_velocity(self, names: Sequence[str], velocities: Sequence[float]) -> str:
        for i, name in enumerate(names):
            limit = self.max_rates.get(name)
            if limit is None or i >= len(velocities):
                continue
            rate = velocities[i]
            if math.isinf(rate) or abs(rate) > limit:
                return f'{name} velocity {rate!r} rad/s is beyond {limit:g} rad/s'
        return ''


class GatedOdometry:
    """
    ``JointStateOdometry`` behind a ``JointStateGate``.

    What the odometry node does with one ``joint_states`` message.

    Parameters
    ----------
    odometry : JointStateOdometry
    max_rates : mapping of str to float
        As for ``JointStateGate``. # [rad/s]

    """

    def __init__(self, odometry: JointStateOdometry, max_rates: Mapping[str, float]) -> None:
        self.odometry = odometry
        self.gate = JointStateGate(max_rates)

    def update(self, t: float, names: Sequence[str], positions: Sequence[float],
               velocities: Sequence[float]) -> tuple[Admission, bool]:
        """
        Return the gate's answer for the message of time ``t`` [s] and whether to publish now.

        An odometry message is never due for a message not integrated.

        Raises
        ------
        ValueError
            As ``JointStateOdometry.update`` (an admitted message it cannot use).

        """
        try:
            self.odometry.check(names, positions, velocities)
        except ImpossibleReading as error:
            return Admission(Verdict.REFUSE, str(error)), False
        last_time = self.gate.last_time
        admission = self.gate.admit(t, names, velocities)
        if admission.verdict in (Verdict.REFUSE, Verdict.REPEAT):
            return admission, False
        if admission.verdict is Verdict.RESTART and t > last_time:
            # Nothing to integrate across the gap; a jump back restarts the core by itself.
            self.odometry.last_time = None
        return admission, self.odometry.update(t, names, positions, velocities)
