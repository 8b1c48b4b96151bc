"""Tracking samples from their topics: the hands, the face, the gripper and the load share
arrive as separate messages stamped with the robot time of their sample; this groups them by
stamp into one :class:`~gazebot.drivers.payloads.TrackingMsg`.

Zenoh keeps the order within a topic, not across topics: once a topic delivered a newer stamp,
it will not deliver an older one. So a sample is complete when

1. every part that currently has a publisher (``expected()``, from the graph) has arrived for
   its stamp or moved on to a newer stamp (a part that is not tracked now is simply not sent),
2. or, while no publisher is known, a part of a newer stamp arrived,
3. or it waited ``timeout`` s of wall time (the last sample before the robot stops).

A part that arrives after its sample was complete is too late: counted in ``late`` and dropped,
unless it is older than the last sample by more than ``clock_reset`` s: then the robot's clock
restarted (a restarted simulator), and the samples start over (the engine node resynchronises).
Stamps are compared to the nanosecond, the resolution of ``builtin_interfaces/Time``.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from gazebot.drivers.payloads import TrackingMsg, point_or_none


@dataclass
class _Pending:
    since: float
    parts: dict[str, Any] = field(default_factory=dict)


class SampleAssembler:
    """Group tracking parts (``giver_hand``, ``receiver_hand``, ``giver_face``: points;
    ``gripper``: bool; ``load_share``: 0..1) by stamp.

    Args:
        expected: The parts that currently have a publisher.
        timeout: Wall time (s) after which a pending sample is complete anyway.
        clock_reset: A part this much older (s) than the last sample starts a new timeline.
        clock: Monotonic clock (s).
    """

    def __init__(self, expected: Callable[[], set[str]], timeout: float = 0.05,
                 clock_reset: float = 0.5,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.expected = expected
        self.timeout = timeout
        self.clock_reset = clock_reset
        self.clock = clock
        self.late = 0
        self._pending: dict[int, _Pending] = {}
        self._newest: dict[str, int] = {}
        self._last_ns: int | None = None
        self._seq = 0

    def add(self, part: str, t: float, value: Any) -> list[TrackingMsg]:
        """Add one part at robot time ``t`` (s); returns the samples it completed, oldest
        first."""
        ns = round(t * 1e9)
        restarted: list[TrackingMsg] = []
        if self._last_ns is not None and ns < self._last_ns - self.clock_reset * 1e9:
            restarted = [self._emit(s) for s in sorted(self._pending)]
            self._last_ns = None
            self._newest.clear()
        elif self._last_ns is not None and ns <= self._last_ns:
            self.late += 1
            return []
        pending = self._pending.setdefault(ns, _Pending(self.clock()))
        pending.parts[part] = value
        self._newest[part] = max(ns, self._newest.get(part, ns))
        expected = self.expected()
        done = []
        for s in sorted(self._pending):
            parts = self._pending[s].parts
            if expected:
                complete = all(p in parts or self._newest.get(p, s) > s for p in expected)
            else:
                complete = s < ns
            if not complete:
                break  # a part still to come for this stamp cannot have come for a newer one
            done.append(s)
        return restarted + [self._emit(s) for s in done]

    def flush_stale(self) -> list[TrackingMsg]:
        """Samples pending for longer than ``timeout``, oldest first."""
        now = self.clock()
        stale = [s for s in sorted(self._pending) if now - self._pending[s].since >= self.timeout]
        if stale:  # everything older than a stale sample is complete too
            stale = [s for s in sorted(self._pending) if s <= stale[-1]]
        return [self._emit(s) for s in stale]

    def next_deadline(self) -> float | None:
        """Clock time at which the oldest pending sample becomes stale (``None``: none)."""
        if not self._pending:
            return None
        return min(p.since for p in self._pending.values()) + self.timeout

    def _emit(self, ns: int) -> TrackingMsg:
        parts = self._pending.pop(ns).parts
        self._last_ns = ns
        sec, nanosec = divmod(ns, 1_000_000_000)
        msg = TrackingMsg(
            seq=self._seq,
            t=float(sec) + 1e-9 * float(nanosec),  # as convert.from_time reads a stamp
            stamp=time.time(),
            giver_hand=point_or_none(parts.get("giver_hand")),
            receiver_hand=point_or_none(parts.get("receiver_hand")),
            giver_face=point_or_none(parts.get("giver_face")),
            gripper_closed=parts.get("gripper"),
            load_share=parts.get("load_share"),
        )
        self._seq += 1
        return msg
