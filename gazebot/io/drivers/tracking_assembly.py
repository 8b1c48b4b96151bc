"""Tracking samples from their topics: the hands, the face, the gripper and the load share
arrive as separate messages stamped with the robot time of their sample; this groups them by
stamp into one :class:`~gazebot.core.types.TrackingFrame`.

Completeness is decided from the stamps, never from how long a sender took between its puts (a
sender stalled on a busy machine must not split its samples). Zenoh keeps the order within a
topic, not across topics: once a topic delivered a newer stamp, it will not deliver an older
one (how far one topic runs ahead of another is not bounded: on a busy machine the callbacks
of different topics run on different threads). The parts a sample waits for are those the
previous sample had (a sender publishes only what it tracks: a body that was not tracked is
not waited for) among those whose topic has a publisher now (``expected()``, from the graph) or
that the source has published so far; the first sample waits for all of them. A sample is
complete when

1. every awaited part arrived for its stamp or its topic moved on to a newer stamp,
2. or ``reorder`` newer samples have arrived meanwhile: an awaited part still missing then is
   no longer tracked (the samples from there on do not wait for it, until it is sent again or
   arrives late), or later than the engine may lag anyway,
3. or nothing at all arrived for ``idle_flush`` s (the last samples before the robot stops, or
   a sender that waits for the answer to each sample).

Until the graph lists a publisher, rule 1 also waits for a newer stamp (a part not seen yet may
still come for this one).

A part that arrives after its sample was complete is too late: counted in ``late`` and dropped.
A part older by more than ``clock_reset`` s than the last one of its own topic means the robot's
clock restarted (a restarted simulator): the samples start over (the engine node
resynchronises). Another topic lagging behind, however far, is only late.
Stamps are compared to 1 ns, the resolution of ``builtin_interfaces/Time``.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from gazebot.core.types import TrackingFrame

#: One part of a sample: a point (m) for a body, the gripper's closure, the load share (0..1).
Part = np.ndarray | bool | float

#: Default idle time (s) after which pending samples are complete anyway.
IDLE_FLUSH = 0.5
#: Default number of newer samples after which an awaited part missing from a sample is
#: untracked: 24 = 0.2 s at 120 Hz (a busy machine starves one topic's callbacks for tens of
#: ms; a body that stops being tracked is waited for this long once).
REORDER = 24


class SampleAssembler:
    """Group tracking parts (``giver_hand``, ``receiver_hand``, ``giver_face``: points;
    ``gripper``: bool; ``load_share``: 0..1) by stamp.

    Args:
        expected: The parts that currently have a publisher.
        idle_flush: Time (s, on ``clock``) without any part arriving after which pending
            samples are complete anyway.
        reorder: Newer samples (stamps) after which a sample is complete whatever is missing.
        clock_reset: A part this much older (s) than the last of its topic starts a new
            timeline.
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
        self._pending: dict[int, dict[str, Part]] = {}
        self._newest: dict[str, int] = {}
        self._seen: set[str] = set()
        self._previous: set[str] | None = None  # the parts of the last sample emitted
        self._last_arrival = 0.0
        self._last_ns: int | None = None

    def add(self, part: str, t: float, value: Part) -> list[TrackingFrame]:
        """Add one part at robot time ``t`` (s); returns the samples it completed, oldest
        first."""
        ns = round(t * 1e9)
        self._last_arrival = self.clock()
        restarted: list[TrackingFrame] = []
        # A restart shows on one topic going back in time (each topic keeps its order); a
        # topic that lags the others, however far, is only late.
        newest = self._newest.get(part)
        if newest is not None and ns < newest - self.clock_reset * 1e9:
            restarted = [self._emit(s) for s in sorted(self._pending)]
            self._last_ns = None
            self._newest.clear()
            self._seen.clear()
            self._previous = None
        elif self._last_ns is not None and ns <= self._last_ns:
            self.late += 1
            if self._previous is not None:  # it lags, it is not lost: wait for it again
                self._previous.add(part)
            return []
        self._pending.setdefault(ns, {})[part] = value
        self._newest[part] = max(ns, self._newest.get(part, ns))
        self._seen.add(part)
        return restarted + [self._emit(s) for s in self._complete()]

    def _complete(self) -> list[int]:
        """The pending stamps that are complete now, oldest first."""
        expected = self.expected()
        stamps = sorted(self._pending)
        done = []
        for i, s in enumerate(stamps):
            newer = len(stamps) - 1 - i
            parts = self._pending[s]
            awaited = expected | self._seen
            if self._previous is not None:
                awaited &= self._previous
            settled = all(p in parts or self._newest.get(p, s) > s for p in awaited)
            if not expected:  # no publisher known yet: a part not seen may still come
                settled = settled and newer > 0
            if not (settled or newer >= self.reorder):
                break  # a part still to come for this stamp cannot have come for a newer one
            done.append(s)
            self._previous = set(parts)
        return done

    def flush_stale(self) -> list[TrackingFrame]:
        """Every pending sample, oldest first, once nothing arrived for ``idle_flush`` s."""
        if not self._pending or self.clock() - self._last_arrival < self.idle_flush:
            return []
        stamps = sorted(self._pending)
        self._previous = set(self._pending[stamps[-1]])
        return [self._emit(s) for s in stamps]

    def next_deadline(self) -> float | None:
        """Clock time at which pending samples are flushed if nothing arrives (``None``:
        none pending)."""
        if not self._pending:
            return None
        return self._last_arrival + self.idle_flush

    def _emit(self, ns: int) -> TrackingFrame:
        parts = self._pending.pop(ns)
        self._last_ns = ns
        sec, nanosec = divmod(ns, 1_000_000_000)
        gripper, share = parts.get("gripper"), parts.get("load_share")
        return TrackingFrame.make(
            float(sec) + 1e-9 * float(nanosec),  # as convert.from_time reads a stamp
            giver_hand=parts.get("giver_hand"),
            receiver_hand=parts.get("receiver_hand"),
            giver_face=parts.get("giver_face"),
            gripper_closed=None if gripper is None else bool(gripper),
            load_share=None if share is None else float(share),
        )
