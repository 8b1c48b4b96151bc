"""A phase segment: one of reach, transfer or retreat of one handover, as a time interval."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from gazebot.core.types import PHASE_OF_EVENT, Event, EventKind, Phase

# The events that start a phase segment (``handover_done`` ends one).
_START_KIND = {k: p for k, p in PHASE_OF_EVENT.items() if p is not Phase.DONE}


@dataclass(frozen=True)
class Segment:
    """A phase interval ``[start, end)`` in seconds.

    Attributes:
        phase: ``reach``, ``transfer`` or ``retreat``.
        start: Phase start (s).
        end: Phase end (s); the next phase of the same handover starts here.
        handover: Index of the handover in the recording (0 for the first).
        detected_at: Online only: when the phase start was detected (s); ``None`` offline.
        open: The data end inside this phase: its end is the last sample, not an observed end.
    """

    phase: Phase
    start: float
    end: float
    handover: int = 0
    detected_at: float | None = None
    open: bool = False

    @property
    def duration(self) -> float:
        """``end - start`` (s)."""
        return self.end - self.start

    def to_json(self) -> dict[str, Any]:
        """The segment as a JSON object (times rounded to 1 us; ``detected_at`` only when set)."""
        out: dict[str, Any] = {
            "phase": self.phase.value,
            "start": round(self.start, 6),
            "end": round(self.end, 6),
            "handover": self.handover,
        }
        if self.detected_at is not None:
            out["detected_at"] = round(self.detected_at, 6)
        return out


def segments_from_events(events: Iterable[Event], t_end: float) -> list[Segment]:
    """Turn a stream of phase events into segments (the online detector's view).

    A phase lasts from its start event to the next phase event (``handover_done`` ends a
    retreat); a phase still open at the end of the data ends at ``t_end``. Tracking events are
    skipped. An end earlier than its start (a back-dated next event) is clipped to the start.
    """
    out: list[Segment] = []
    open_phase: tuple[Phase, float, float] | None = None
    handover = -1
    for ev in events:
        if ev.kind in (EventKind.TRACKING_LOST, EventKind.TRACKING_RESTORED):
            continue
        if ev.kind not in _START_KIND and ev.kind is not EventKind.HANDOVER_DONE:
            continue
        if open_phase is not None:
            phase, start, det = open_phase
            out.append(Segment(phase, start, max(start, ev.t), max(handover, 0), det))
            open_phase = None
        if ev.kind is EventKind.REACH_STARTED:
            handover += 1
        elif ev.kind is EventKind.TRANSFER_STARTED and (not out or out[-1].phase is Phase.RETREAT):
            handover += 1  # a transfer seen without its reach
        if ev.kind in _START_KIND:
            open_phase = (_START_KIND[ev.kind], ev.t, ev.detected_at)
    if open_phase is not None and math.isfinite(t_end):
        phase, start, det = open_phase
        out.append(Segment(phase, start, max(start, t_end), max(handover, 0), det, open=True))
    return out
