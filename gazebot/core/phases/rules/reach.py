"""Idle -> reach: when the giver's reach starts.

The reach starts at the giver's motion onset before the transfer: the fastest motion in the
window, from the last sample *seen* slower than ``reach_onset_speed``, back-dated from the last
rest sample (speed under ``rest_speed``) with the minimum-jerk start ``t0 = t - 3 x / v`` (at
most ``max_refine``); an onset hidden in a tracking gap is dated across the gap. A giver that
never moved fast there leaves the receiver's onset (never the window's start). A reach still
under way when the data end (no transfer yet) is one where the hands have closed by
``reach_confirm_distance`` while the giver's hand moves toward the receiver, or by
``min_approach`` after the giver's hand moved; and they are at their closest at the end.
"""

from __future__ import annotations

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import Signals, nanmax, nanmin, vector_norm
from gazebot.core.phases.rules.onset import min_jerk_span


def reach_start(s: Signals, c: PhaseConfig, lo: int, hi: int) -> float:
    """Start of the giver's reach before grid index ``hi`` (not before index ``lo``).

    A giver whose hand never moved faster than ``reach_onset_speed`` there (it held the object
    out already and the receiver came to take it) has no onset of its own: the receiver's
    onset dates the reach then, and with neither hand moving it starts at ``hi``. Never the
    window's start: that would date a reach seconds before anyone moved (a robot-initiated
    handover closes the gap before the giver moves fast)."""
    if hi <= lo:
        return float(s.t[lo])
    for speed, pos in ((s.giver_speed, s.giver), (s.receiver_speed, s.receiver)):
        onset = _onset(s, c, speed, pos, lo, hi)
        if onset is not None:
            return onset
    return float(s.t[hi])


def _onset(
    s: Signals, c: PhaseConfig, speed: np.ndarray, pos: np.ndarray, lo: int, hi: int
) -> float | None:
    """Motion onset of one hand before ``hi`` (see the module docstring), ``None`` if that
    hand never moved faster than ``reach_onset_speed`` in ``[lo, hi]``."""
    v = speed[lo : hi + 1]
    if not nanmax(v, initial=0.0) >= c.reach_onset_speed:
        return None
    peak = int(np.nanargmax(v))
    head = v[: peak + 1]
    seen = np.isfinite(head)
    slow = (seen & (head < c.reach_onset_speed)).nonzero()[0]
    if slow.size:
        i_c = lo + int(slow[-1]) + 1 + int(seen[slow[-1] + 1 :].argmax())
    else:
        slow = (~seen).nonzero()[0]  # only a gap before the motion: it may hide the onset
        if slow.size == 0:
            return float(s.t[lo])  # already moving when the data start
        i_c = lo + int(slow[-1]) + 1
    rest = (speed[lo:i_c] < c.rest_speed).nonzero()[0]
    i_r = lo + int(rest[-1]) if rest.size else lo
    x = vector_norm(pos[i_c] - pos[i_r])
    back = min_jerk_span(x, float(speed[i_c]), c.max_refine)
    floor = float(s.t[lo])
    if i_c - i_r > 1 and not np.isfinite(speed[i_r + 1 : i_c]).all():
        floor = max(floor, float(s.t[i_r]))
    return max(float(s.t[i_c]) - back, floor)


def trailing_reach(s: Signals, c: PhaseConfig, lo: int) -> float | None:
    """Onset of a reach still under way when the data end (after grid index ``lo``), else
    ``None``: the hands have closed by ``reach_confirm_distance`` from their farthest since
    ``lo`` and are at their closest now, and the giver's hand has itself moved toward the
    receiver by ``approach_ratio`` of that distance, the hands closing and the giver's hand
    moving faster than ``reach_onset_speed`` within the last ``smoothing`` window (or, when
    the receiver did the closing, the giver's hand moved faster than ``reach_onset_speed``
    and the hands closed by ``min_approach``)."""
    d = s.distance[lo:]
    seen = np.isfinite(d).nonzero()[0]
    if seen.size < 3:
        return None
    i_max = int(np.nanargmax(d))
    i_last = int(seen[-1])
    last = float(d[i_last])
    closed = float(d[i_max]) - last
    if (
        closed < c.reach_confirm_distance
        or last > float(nanmin(d[i_max:])) + c.reach_confirm_distance
    ):
        return None
    k = lo + i_last
    # The giver's own share of the closing: its displacement since the hands were farthest,
    # along the line to the receiver (a robot moving in past a resting giver closes them too).
    u = s.rel[k] / max(float(d[i_last]), 1e-9)
    own = float(np.dot(s.giver[k] - s.giver[lo + i_max], u))
    # ... and the hands closing at a reach's speed now (a drift or fidget is slower).
    j0 = max(lo + i_max, k - int(round(c.smoothing * c.analysis_rate)))
    closing = s.closing[j0 : k + 1]  # (-d distance / dt: rel_v along rel)
    fast = bool(nanmax(closing, initial=0.0) >= c.reach_onset_speed) and bool(
        nanmax(s.giver_speed[j0 : k + 1], initial=0.0) >= c.reach_onset_speed
    )
    moving = fast and own >= c.approach_ratio * c.reach_confirm_distance
    if not moving:
        if closed < c.min_approach:
            return None
        if not nanmax(s.giver_speed[lo + i_max :], initial=0.0) >= c.reach_onset_speed:
            return None  # only the receiver came closer
    return reach_start(s, c, lo + i_max, k)
