"""Comparing detected phase events with the synthetic ground truth (shared by the online tests)."""

from __future__ import annotations

import numpy as np

from gazebot.core.types import EventKind

PHASE_KINDS = (
    EventKind.REACH_STARTED,
    EventKind.TRANSFER_STARTED,
    EventKind.RETREAT_STARTED,
    EventKind.HANDOVER_DONE,
)
# The HandoverTruth field each phase event estimates.
TRUTH_FIELD = {
    EventKind.REACH_STARTED: "reach_start",
    EventKind.TRANSFER_STARTED: "transfer_start",
    EventKind.RETREAT_STARTED: "transfer_end",
    EventKind.HANDOVER_DONE: "retreat_end",
}


def event_errors(cases, results, kind) -> tuple[np.ndarray, np.ndarray]:
    """(|t - truth|, detected_at - truth) arrays for one event kind over the set."""
    err, lat = [], []
    for case, res in zip(cases, results, strict=True):
        evs = [e for e in res.events if e.kind is kind]
        for e, h in zip(evs, case.truth, strict=True):
            truth = getattr(h, TRUTH_FIELD[kind])
            err.append(abs(e.t - truth))
            lat.append(e.detected_at - truth)
    return np.array(err), np.array(lat)
