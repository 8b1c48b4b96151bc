"""The seed's section 7.2.5 rule read from its sentence alone, to check ``--method seed-7.2.5``.

The sentence: "the 'transfer' phase corresponds to the portion of the handover where the
distance between the giver's and receiver's hands is within 20cm of the minimum distance, and
their relative velocity is less than 15cm/s."

Read literally, for ONE handover: take the minimum distance over that handover; the transfer
is the portion of the samples with distance <= minimum + 0.20 m and relative speed < 0.15 m/s.
The sentence leaves three things open; each is a parameter here, and every test that calls
this states the value it passes and why:

- ``handover``: which samples form "the handover" (the seed cut its recordings by hand). The
  caller passes a time window (tests: the generator's known handover windows, or the whole KTH
  sample, which holds one handover).
- ``half``: how "relative velocity" is measured. Here the central difference
  ``|p(t + half) - p(t - half)| / (2 half)`` of the relative position, taking the samples
  *nearest* to ``t +- half`` (no interpolation); the caller passes ``half``.
- "portion" as an interval: here the span from the first to the last qualifying sample (the
  widest reading); :func:`qualifying_runs` gives the runs inside it when a test needs them.

Missing samples (NaN) are dropped. Plain Python, nothing imported from gazebot.
"""

from __future__ import annotations

import bisect
import math


def _rows(t, giver, receiver, window):
    lo, hi = window
    ts, ps = [], []
    for ti, g, r in zip(t, giver, receiver, strict=True):
        if lo <= ti <= hi and all(math.isfinite(v) for v in (*g, *r)):
            ts.append(float(ti))
            ps.append(tuple(float(b - a) for a, b in zip(g, r, strict=True)))
    return ts, ps


def _nearest(ts, x):
    i = bisect.bisect_left(ts, x)
    if i == 0:
        return 0
    if i == len(ts):
        return len(ts) - 1
    return i if ts[i] - x < x - ts[i - 1] else i - 1


def qualifying(t, giver, receiver, handover, half, margin=0.20, vmax=0.15):
    """``[(time, qualifies)]`` over the handover window (``qualifies``: within ``margin`` of
    the window's minimum distance and slower than ``vmax``; samples whose ``t +- half`` leave
    the window do not qualify)."""
    ts, ps = _rows(t, giver, receiver, handover)
    if not ts:
        return []
    d = [math.sqrt(sum(c * c for c in p)) for p in ps]
    d_min = min(d)
    out = []
    for i, ti in enumerate(ts):
        if ti - half < ts[0] or ti + half > ts[-1]:
            out.append((ti, False))
            continue
        a, b = ps[_nearest(ts, ti - half)], ps[_nearest(ts, ti + half)]
        dt = ts[_nearest(ts, ti + half)] - ts[_nearest(ts, ti - half)]
        v = math.sqrt(sum((y - x) ** 2 for x, y in zip(a, b, strict=True))) / dt
        out.append((ti, d[i] <= d_min + margin and v < vmax))
    return out


def seed_transfer(t, giver, receiver, handover, half, margin=0.20, vmax=0.15):
    """``(start, end)``: first and last qualifying sample of the handover, or ``None``."""
    q = [ti for ti, ok in qualifying(t, giver, receiver, handover, half, margin, vmax) if ok]
    return (q[0], q[-1]) if q else None


def qualifying_runs(t, giver, receiver, handover, half, margin=0.20, vmax=0.15):
    """The contiguous runs of qualifying samples, as ``[(start, end)]`` in time order."""
    runs, start, prev = [], None, None
    for ti, ok in qualifying(t, giver, receiver, handover, half, margin, vmax):
        if ok and start is None:
            start = ti
        if not ok and start is not None:
            runs.append((start, prev))
            start = None
        prev = ti
    if start is not None:
        runs.append((start, prev))
    return runs
