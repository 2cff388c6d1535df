"""
Matching the planner's inputs by their stamps, so that each climb step sees one moment.

The planner acts once per controller state (the controller answers every joint_states). For
a tick at time t it takes, from every input topic, the newest message stamped at or before t,
and it waits until every topic has been heard at or after t, so a message of that moment
still on its way cannot be missed. In a lockstep sim (all stamps equal per cycle) that is
exactly the state of time t, whatever the machine's load; on hardware with inputs of other
rates it waits at most one period of the slowest input.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
import math
from typing import Any, Iterable


@dataclass(frozen=True)
class Tick:
    """One moment with a value from every input topic."""

    time: float  # [s]
    values: dict[str, Any]


class InputSync:
    """
    Collects stamped inputs and hands out the ticks whose inputs are complete.

    Parameters
    ----------
    topics : iterable of str
        Every input; ``tick_topic`` among them.
    tick_topic : str
        The topic whose messages make ticks.
    depth : int
        Messages kept per topic, and ticks kept waiting; older ones are dropped.

    """

    def __init__(self, topics: Iterable[str], tick_topic: str, depth: int = 50) -> None:
        if depth < 1:
            raise ValueError(f'depth must be >= 1, got {depth!r}')
        self._buffers: dict[str, deque[tuple[float, Any]]] = {
            topic: deque(maxlen=depth) for topic in topics}
        if tick_topic not in self._buffers:
            raise ValueError(f'tick topic {tick_topic!r} is not among the inputs')
        self._tick_topic = tick_topic
        self._pending: deque[float] = deque(maxlen=depth)
        self._last_tick = -math.inf  # [s]

    def add(self, topic: str, stamp: float, value: Any) -> list[Tick]:
        """
        Take one message (stamp [s]); returns the ticks it completed, oldest first.

        A stamp older than the topic's newest means time went back (a sim reset): everything
        collected so far is dropped.
        """
        buffer = self._buffers[topic]
        if buffer and stamp < buffer[-1][0]:
            self.clear()
        buffer.append((stamp, value))
        if topic == self._tick_topic and stamp > self._last_tick:
            self._pending.append(stamp)
        return self._ready_ticks()

    def describe(self) -> str:
        """Each topic's newest stamp and the oldest waiting tick, for error messages."""
        newest = ', '.join(f'{topic} {buffer[-1][0]:.2f} s' if buffer else f'{topic} none'
                           for topic, buffer in self._buffers.items())
        waiting = f'{self._pending[0]:.2f} s' if self._pending else 'none'
        return f'newest stamps: {newest}; oldest waiting tick {waiting}'

    def clear(self) -> None:
        for buffer in self._buffers.values():
            buffer.clear()
        self._pending.clear()
        self._last_tick = -math.inf

    def _ready_ticks(self) -> list[Tick]:
        ticks = []
        while self._pending:
            t = self._pending[0]
            if any(not buffer or buffer[-1][0] < t for buffer in self._buffers.values()):
                break
            self._pending.popleft()
            if t <= self._last_tick:
                continue
            values = {topic: _newest_until(buffer, t) for topic, buffer in self._buffers.items()}
            if any(value is _MISSING for value in values.values()):
                continue  # a topic's messages of that moment were dropped: skip it
            self._last_tick = t
            ticks.append(Tick(t, values))
        return ticks


_MISSING = object()


def _newest_until(buffer: deque[tuple[float, Any]], t: float) -> Any:
    for stamp, value in reversed(buffer):
        if stamp <= t:
            return value
    return _MISSING
