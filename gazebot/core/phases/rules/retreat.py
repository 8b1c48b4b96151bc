"""Retreat -> done: when the giver's retreat ends.

At the earliest of: the giver's hand back at rest (its speed under ``rest_speed`` after
moving faster than ``reach_onset_speed``; dated forward from the last fast sample with the
minimum-jerk stop ``3 x / v``), the hand ``retreat_far_distance`` from where the transfer
happened, ``max_retreat`` after the release, the next reach, and the data end.
"""

from __future__ import annotations

import math

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import Signals, vector_norm
from gazebot.core.phases.rules.onset import min_jerk_span


def rest_after(s: Signals, c: PhaseConfig, lo: int, hi: int) -> tuple[float, bool]:
    """End of the giver's first motion after grid index ``lo`` (not after index ``hi``), and
    whether that end was seen (``False``: still moving when the data or window end)."""
    hi = min(hi, lo + int(c.max_retreat * c.analysis_rate), s.t.shape[0] - 1)
    v = s.giver_speed[lo : hi + 1]
    fast = (v >= c.reach_onset_speed).nonzero()[0]
    if hi <= lo or fast.size == 0:
        return float(s.t[hi]), hi < s.t.shape[0] - 1
    tail = v[fast[0] :]
    rest = (tail < c.rest_speed).nonzero()[0]
    if rest.size == 0 and not (tail[-1] < c.reach_onset_speed):
        return float(s.t[hi]), hi < s.t.shape[0] - 1
    i_r = lo + int(fast[0]) + (int(rest[0]) if rest.size else tail.size - 1)
    moving = (s.giver_speed[lo + int(fast[0]) : i_r + 1] >= c.reach_onset_speed).nonzero()[0]
    i_c = lo + int(fast[0]) + int(moving[-1])
    x = vector_norm(s.giver[i_r] - s.giver[i_c])
    fwd = min_jerk_span(x, float(s.giver_speed[i_c]), c.max_refine)
    seen = rest.size > 0 or hi < s.t.shape[0] - 1
    return min(float(s.t[i_c]) + fwd, float(s.t[hi])), seen


def far_after(s: Signals, c: PhaseConfig, i_end: int) -> float:
    """First time after grid index ``i_end`` (the release) that the giver's hand is
    ``retreat_far_distance`` from where the transfer happened (``inf`` if never)."""
    # the last sample seen at or before the release, searched from it (usually that one)
    k = min(i_end, s.t.shape[0] - 1)
    while k >= 0 and not all(map(math.isfinite, s.giver[k].tolist())):
        k -= 1
    if k < 0:
        return math.inf
    moved = np.linalg.norm(s.giver[i_end:] - s.giver[k], axis=1)
    far = (moved >= c.retreat_far_distance).nonzero()[0]
    return float(s.t[i_end + int(far[0])]) if far.size else math.inf


def retreat_done(
    s: Signals, c: PhaseConfig, t_release: float, joined_late: bool = False
) -> tuple[float, str] | None:
    """The end of a retreat that started at ``t_release``, as far as the data show it:
    ``(time, source)`` with source ``rest``, ``far`` or ``landing`` (:func:`_landing`), or
    ``None`` while it goes on.

    When the release predates the data, or ``joined_late`` (an engine restarted mid-retreat),
    the hand's motion since the release is unknown: a hand at rest (under ``rest_speed`` for
    ``rest_hold``) ends the retreat.
    """
    n = s.t.shape[0]
    if n < 2:
        return None
    i0 = int(s.t.searchsorted(t_release))
    if i0 >= n - 1:
        return None
    t_rest, seen = rest_after(s, c, i0, n - 1)
    landing = _landing(s, c, i0, t_release)
    late = joined_late or t_release < s.t[0]
    t_far = far_after(s, c, i0) if not late else math.inf
    best: tuple[float, str] | None = None
    if seen and t_rest < s.t[-1]:
        best = (t_rest, "rest")
    if math.isfinite(t_far) and (best is None or t_far < best[0]):
        best = (t_far, "far")
    if landing is not None and (best is None or landing < best[0]):
        best = (landing, "landing")
    if best is None and late:
        v = s.giver_speed
        hold = int(round(c.rest_hold * c.analysis_rate))
        slow = np.isfinite(v) & (v < c.rest_speed)
        if n > hold and slow[-hold - 1 :].all():
            k = n - 1
            while k > i0 and slow[k - 1]:
                k -= 1
            best = (max(float(s.t[k]), t_release), "rest")
    return best


def _landing(s: Signals, c: PhaseConfig, i0: int, t_release: float) -> float | None:
    """A predicted landing: the giver's hand, having moved ``min_approach`` since the release,
    slowed below ``done_fraction`` of its peak speed. A bell-shaped (minimum-jerk) profile is
    then within a few percent of its end, which mirrors the onset about the peak:
    ``t_release + 2 (t_peak - t_release)`` (not after the newest sample)."""
    if t_release < s.t[0]:
        return None
    v = s.giver_speed[i0:]
    ok = np.isfinite(v)
    if not ok.any():
        return None
    k = int(np.nanargmax(v))
    peak = float(v[k])
    last = int(ok.nonzero()[0][-1])
    moved = vector_norm(s.giver[i0 + last] - s.giver[i0])
    if peak < c.reach_onset_speed or last <= k or not moved >= c.min_approach:
        return None
    if not v[last] < c.done_fraction * peak:
        return None
    # (not after the newest sample: online the signals end edge_guard before it, and the
    # mirror is dated from the whole profile, not from when the analysis happened to run)
    return min(t_release + 2.0 * (float(s.t[i0 + k]) - t_release), float(s.t[-1]) + c.edge_guard)
