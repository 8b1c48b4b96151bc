"""Retreat -> done: when the giver's retreat ends.

At the earliest of: the giver's hand back at rest (its speed under ``rest_speed`` after
moving faster than ``reach_onset_speed``; dated forward from the last fast sample with the
minimum-jerk stop ``3 x / v``), the hand ``retreat_far_distance`` from where the transfer
happened, ``max_retreat`` after the release, the next reach, and the data end.
"""

from __future__ import annotations

import math

import numpy as np

from gazebot.phases.config import PhaseConfig
from gazebot.phases.filtering import Signals


def rest_after(s: Signals, c: PhaseConfig, lo: int, hi: int) -> tuple[float, bool]:
    """End of the giver's first motion after grid index ``lo`` (not after index ``hi``), and
    whether that end was seen (``False``: still moving when the data or window end)."""
    hi = min(hi, lo + int(c.max_retreat * c.analysis_rate), s.t.shape[0] - 1)
    v = s.giver_speed[lo : hi + 1]
    fast = np.flatnonzero(v >= c.reach_onset_speed)
    if hi <= lo or fast.size == 0:
        return float(s.t[hi]), hi < s.t.shape[0] - 1
    tail = v[fast[0] :]
    rest = np.flatnonzero(tail < c.rest_speed)
    if rest.size == 0 and not (tail[-1] < c.reach_onset_speed):
        return float(s.t[hi]), hi < s.t.shape[0] - 1
    i_r = lo + int(fast[0]) + (int(rest[0]) if rest.size else tail.size - 1)
    moving = np.flatnonzero(s.giver_speed[lo + int(fast[0]) : i_r + 1] >= c.reach_onset_speed)
    i_c = lo + int(fast[0]) + int(moving[-1])
    x = float(np.linalg.norm(s.giver[i_r] - s.giver[i_c]))
    speed = float(s.giver_speed[i_c])
    fwd = 3.0 * x / speed if math.isfinite(x) and speed > 0 else 0.0
    seen = rest.size > 0 or hi < s.t.shape[0] - 1
    return min(float(s.t[i_c]) + min(fwd, c.max_refine), float(s.t[hi])), seen


def far_after(s: Signals, c: PhaseConfig, i_end: int) -> float:
    """First time after grid index ``i_end`` (the release) that the giver's hand is
    ``retreat_far_distance`` from where the transfer happened (``inf`` if never)."""
    seen = np.flatnonzero(np.isfinite(s.giver[: i_end + 1]).all(axis=1))
    if seen.size == 0:
        return math.inf
    moved = np.linalg.norm(s.giver[i_end:] - s.giver[int(seen[-1])], axis=1)
    far = np.flatnonzero(moved >= c.retreat_far_distance)
    return float(s.t[i_end + int(far[0])]) if far.size else math.inf
