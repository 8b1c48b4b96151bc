"""End-of-phase prediction (``expected_phase_end``).

Reach and retreat follow roughly symmetric bell-shaped (minimum-jerk) speed profiles: once a
hand's speed has fallen below ``peak_passed_fraction`` of its peak, the motion ends about as
long after the peak as the peak came after the onset (``onset + 2 (t_peak - onset)``); before
that, the onset plus the typical reach (retreat) duration of :mod:`gazebot.core.phases.durations`.
A reach ends at contact, so it is the later of the giver's and the receiver's predicted
arrivals (the receiver's onset is where its own speed first exceeded ``reach_onset_speed``). A
transfer is predicted to last the typical transfer. Never earlier than now; NaN in ``idle``
and ``done``.
"""

from __future__ import annotations

import math

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.durations import REACH_S, RETREAT_S, TRANSFER_S
from gazebot.core.phases.filtering import Signals
from gazebot.core.types import Phase


def _mirrored(
    t: np.ndarray, v: np.ndarray, onset: float, nominal: float, now: float, c: PhaseConfig
) -> float:
    # The speed is read no nearer the newest sample (``now``) than the smoothing window: the
    # last stretch of a one-sided Gaussian window sags, and a sag read as "past its peak" would
    # mirror the onset about a peak not yet reached (how early depends on when the analysis
    # happened to run). (t is sorted: the samples read are a prefix.)
    k = int(t.searchsorted(now - c.smoothing, side="right"))
    t, v = t[:k], v[:k]
    if not k:
        return onset + nominal
    known = np.flatnonzero(np.isfinite(v))
    if known.size == 0:
        return onset + nominal
    i = int(np.nanargmax(v))  # the peak speed (NaN: unknown)
    peak = float(v[i])
    last = float(v[known[-1]])  # the last known speed
    if peak > c.reach_onset_speed and last < c.peak_passed_fraction * peak:
        return onset + 2.0 * max(float(t[i]) - onset, 0.0)
    return onset + nominal


def predict_end(phase: Phase, start: float, s: Signals | None, now: float, c: PhaseConfig) -> float:
    """Predicted end of ``phase`` that started at ``start`` (s), from the signals so far."""
    if phase is Phase.TRANSFER:
        return max(start + TRANSFER_S, now)
    if phase not in (Phase.REACH, Phase.RETREAT) or not math.isfinite(start):
        return math.nan
    nominal = REACH_S if phase is Phase.REACH else RETREAT_S
    if s is None or s.t.shape[0] == 0:
        return max(start + nominal, now)
    i0 = int(s.t.searchsorted(start))
    pred = _mirrored(s.t[i0:], s.giver_speed[i0:], start, nominal, now, c)
    if phase is Phase.REACH:
        j0 = int(s.t.searchsorted(start - nominal))
        moving = s.receiver_speed[j0:] >= c.reach_onset_speed
        first = int(moving.argmax()) if moving.shape[0] else 0  # the first True, if any
        if moving.shape[0] and moving[first]:
            k0 = j0 + first
            r_on = float(s.t[k0])
            pred = max(pred, _mirrored(s.t[k0:], s.receiver_speed[k0:], r_on, nominal, now, c))
    return max(pred, now)
