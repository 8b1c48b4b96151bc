"""An independent implementation of the seed's section 7.2.5 rule, written from the sentence
("within 20cm of the minimum distance, and their relative velocity is less than 15cm/s") for
checking ``--method seed-7.2.5``. Plain Python loops, no code shared with gazebot."""

from __future__ import annotations

import bisect
import math


def _lerp(ts: list[float], ps: list[tuple[float, float, float]], x: float):
    i = bisect.bisect_left(ts, x)
    if i < len(ts) and abs(ts[i] - x) < 1e-12:
        return ps[i]
    if i == 0 or i == len(ts):
        return None
    w = (x - ts[i - 1]) / (ts[i] - ts[i - 1])
    return tuple(a + w * (b - a) for a, b in zip(ps[i - 1], ps[i], strict=True))


def seed_transfers(t, giver, receiver, margin=0.20, vmax=0.15, h=0.05):
    """``[(start, end)]`` of the transfer of each handover (one per dip of the distance)."""
    ts, ps = [], []
    for ti, g, r in zip(t, giver, receiver, strict=True):
        if all(math.isfinite(v) for v in (*g, *r)):
            ts.append(float(ti))
            ps.append(tuple(float(b - a) for a, b in zip(g, r, strict=True)))
    n = len(ts)
    d = [math.sqrt(sum(c * c for c in p)) for p in ps]
    v = []
    for i in range(n):
        a, b = _lerp(ts, ps, ts[i] - h), _lerp(ts, ps, ts[i] + h)
        if a is None or b is None:
            v.append(math.inf)
        else:
            v.append(math.sqrt(sum((y - x) ** 2 for x, y in zip(a, b, strict=True))) / (2 * h))
    # Handovers: from the lowest unassigned minimum, the region within 20 cm of it.
    assigned = [False] * n
    out = []
    for i0 in sorted(range(n), key=lambda i: d[i]):
        if assigned[i0]:
            continue
        lim = d[i0] + margin
        lo = i0
        while lo > 0 and not assigned[lo - 1] and d[lo - 1] <= lim:
            lo -= 1
        hi = i0
        while hi < n - 1 and not assigned[hi + 1] and d[hi + 1] <= lim:
            hi += 1
        bounded = (lo > 0 and d[lo - 1] > lim) or (hi < n - 1 and d[hi + 1] > lim)
        touching = (lo > 0 and assigned[lo - 1]) or (hi < n - 1 and assigned[hi + 1])
        for i in range(lo, hi + 1):
            assigned[i] = True
        if not bounded or touching:
            continue
        best, run_start = None, None
        for i in range(lo, hi + 2):
            slow = i <= hi and v[i] < vmax
            if slow and run_start is None:
                run_start = i
            if not slow and run_start is not None:
                if best is None or i - 1 - run_start > best[1] - best[0]:
                    best = (run_start, i - 1)
                run_start = None
        if best is not None:
            out.append((ts[best[0]], ts[best[1]]))
    return sorted(out)
