"""Idle -> reach: when the giver's reach starts.

The reach starts at the giver's motion onset before the transfer: the fastest motion in the
window, from the last sample *seen* slower than ``reach_onset_speed``, back-dated from the last
rest sample (speed under ``rest_speed``) with the minimum-jerk start ``t0 = t - 3 x / v`` (at
most ``max_refine``); an onset hidden in a tracking gap is dated across the gap. A reach still
under way when the data end (no transfer yet) is one where the giver's hand moved, the hands
closed by at least ``min_approach`` and are at their closest at the end.
"""

from __future__ import annotations

import math

import numpy as np

from gazebot.phases.config import PhaseConfig
from gazebot.phases.filtering import Signals


def reach_start(s: Signals, c: PhaseConfig, lo: int, hi: int) -> float:
    """Start of the giver's reach before grid index ``hi`` (not before index ``lo``)."""
    v = s.giver_speed[lo : hi + 1]
    if hi <= lo or not np.nanmax(v, initial=0.0) >= c.reach_onset_speed:
        return float(s.t[lo])
    peak = int(np.nanargmax(v))
    head = v[: peak + 1]
    seen = np.isfinite(head)
    slow = np.flatnonzero(seen & (head < c.reach_onset_speed))
    if slow.size:
        i_c = lo + int(slow[-1]) + 1 + int(np.argmax(seen[slow[-1] + 1 :]))
    else:
        slow = np.flatnonzero(~seen)  # only a gap before the motion: it may hide the onset
        if slow.size == 0:
            return float(s.t[lo])  # already moving when the data start
        i_c = lo + int(slow[-1]) + 1
    rest = np.flatnonzero(s.giver_speed[lo:i_c] < c.rest_speed)
    i_r = lo + int(rest[-1]) if rest.size else lo
    x = float(np.linalg.norm(s.giver[i_c] - s.giver[i_r]))
    speed = float(s.giver_speed[i_c])
    back = 3.0 * x / speed if math.isfinite(x) and speed > 0 else 0.0
    floor = float(s.t[lo])
    if i_c - i_r > 1 and not np.isfinite(s.giver_speed[i_r + 1 : i_c]).all():
        floor = max(floor, float(s.t[i_r]))
    return max(float(s.t[i_c]) - min(back, c.max_refine), floor)


def trailing_reach(s: Signals, c: PhaseConfig, lo: int) -> float | None:
    """Onset of a reach still under way when the data end (after grid index ``lo``), else
    ``None`` (see the module docstring)."""
    d = s.distance[lo:]
    seen = np.flatnonzero(np.isfinite(d))
    if seen.size < 3:
        return None
    i_max = int(np.nanargmax(d))
    last = float(d[seen[-1]])
    tail_min = float(np.nanmin(d[i_max:]))
    if d[i_max] - last < c.min_approach or last > tail_min + 0.5 * c.min_approach:
        return None
    if not np.nanmax(s.giver_speed[lo + i_max :], initial=0.0) >= c.reach_onset_speed:
        return None  # only the receiver came closer
    return reach_start(s, c, lo, lo + int(seen[-1]))
