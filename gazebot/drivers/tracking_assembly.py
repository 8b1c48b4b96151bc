"""Tracking samples from their topics: the hands, the face, the gripper and the load share
arrive as separate messages stamped with the robot time of their sample; this groups them by
stamp into one :class:`~gazebot.drivers.payloads.TrackingMsg`.

Completeness is decided from the stamps, never from how long a sender took between its puts (a
sender stalled on a busy machine must not split its samples). Zenoh keeps the order within a
topic, not across topics: once a topic delivered a newer stamp, it will not deliver an older
one. The parts a sample can have are those whose topic has a publisher now (``expected()``,
from the graph) and those the source has published so far. A sample is complete when

1. every such part arrived for its stamp or its topic moved on to a newer stamp,
2. or ``reorder`` newer samples have arrived meanwhile: a part still missing then is not
   tracked at this stamp (a sender publishes only what it tracks), not late; ``reorder`` is
   how far one topic may run ahead of another,
3. or nothing at all arrived for ``idle_flush`` s (the last samples before the robot stops, or
   a sender that waits for the answer to each sample).

Until the graph lists a publisher, rule 1 also waits for a newer stamp (a part not seen yet may
still come for this one).

A part that arrives after its sample was complete is too late: counted in ``late`` and dropped,
unless it is older than the last sample by more than ``clock_reset`` s: then the robot's clock
restarted (a restarted simulator), and the samples start over (the engine node resynchronises).
Stamps are compared to the nanosecond, the resolution of ``builtin_interfaces/Time``.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from gazebot.drivers.payloads import TrackingMsg, point_or_none

#: Default idle time (s) after which pending samples are complete anyway.
IDLE_FLUSH = 0.5
#: Default number of newer samples after which a part missing from a sample is untracked.
REORDER = 3


class SampleAssembler:
    """Group tracking parts (``giver_hand``, ``receiver_hand``, ``giver_face``: points;
    ``gripper``: bool; ``load_share``: 0..1) by stamp.

    Args:
        expected: The parts that currently have a publisher.
        idle_flush: Time (s, on ``clock``) without any part arriving after which pending
            samples are complete anyway.
        reorder: Newer samples (stamps) after which a sample is complete whatever is missing.
        clock_reset: A part this much older (s) than the last sample starts a new timeline.
        clock: Monotonic clock (s).
    """

    def __init__(self, expected: Callable[[], set[str]], idle_flush: float = IDLE_FLUSH,
                 reorder: int = REORDER, clock_reset: float = 0.5,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if not idle_flush > 0.0:
            raise ValueError(f"idle_flush must be > 0 s, got {idle_flush}")
        if reorder < 1:
            raise ValueError(f"reorder must be >= 1 sample, got {reorder}")
        self.expected = expected
        self.idle_flush = idle_flush
        self.reorder = reorder
        self.clock_reset = clock_reset
        self.clock = clock
        self.late = 0
        self._pending: dict[int, dict[str, Any]] = {}
        self._newest: dict[str, int] = {}
        self._seen: set[str] = set()
        self._last_arrival = 0.0
        self._last_ns: int | None = None
        self._seq = 0

    def add(self, part: str, t: float, value: Any) -> list[TrackingMsg]:
        """Add one part at robot time ``t`` (s); returns the samples it completed, oldest
        first."""
        ns = round(t * 1e9)
        self._last_arrival = self.clock()
        restarted: list[TrackingMsg] = []
        if self._last_ns is not None and ns < self._last_ns - self.clock_reset * 1e9:
            restarted = [self._emit(s) for s in sorted(self._pending)]
            self._last_ns = None
            self._newest.clear()
            self._seen.clear()
        elif self._last_ns is not None and ns <= self._last_ns:
            self.late += 1
            return []
        self._pending.setdefault(ns, {})[part] = value
        self._newest[part] = max(ns, self._newest.get(part, ns))
        self._seen.add(part)
        return restarted + [self._emit(s) for s in self._complete()]

    def _complete(self) -> list[int]:
        """The pending stamps that are complete now, oldest first."""
        expected = self.expected()
        parts_of = expected | self._seen
        stamps = sorted(self._pending)
        done = []
        for i, s in enumerate(stamps):
            newer = len(stamps) - 1 - i
            parts = self._pending[s]
            settled = all(p in parts or self._newest.get(p, s) > s for p in parts_of)
            if not expected:  # no publisher known yet: a part not seen may still come
                settled = settled and newer > 0
            if not (settled or newer >= self.reorder):
                break  # a part still to come for this stamp cannot have come for a newer one
            done.append(s)
        return done

    def flush_stale(self) -> list[TrackingMsg]:
        """Every pending sample, oldest first, once nothing arrived for ``idle_flush`` s."""
        if not self._pending or self.clock() - self._last_arrival < self.idle_flush:
            return []
        return [self._emit(s) for s in sorted(self._pending)]

    def next_deadline(self) -> float | None:
        """Clock time at which pending samples are flushed if nothing arrives (``None``:
        none pending)."""
        if not self._pending:
            return None
        return self._last_arrival + self.idle_flush

    def _emit(self, ns: int) -> TrackingMsg:
        parts = self._pending.pop(ns)
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
