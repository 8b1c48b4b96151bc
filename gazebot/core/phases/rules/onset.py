"""The minimum-jerk onset (and stop) estimate every rule uses to date a motion's ends.

Near either end of a minimum-jerk motion the distance covered grows with the cube of the time
since its start (or left to its stop): ``x ~ k (t - t0)^3``, so the speed is ``v = 3 x / (t -
t0)`` and the motion started ``3 x / v`` before a sample where it had covered ``x`` at speed
``v`` (or stops ``3 x / v`` after a sample with ``x`` left to go). One helper, so the reach
onset, the release, the retreat's end and an approach stopping inside a tracking gap are dated
the same way.
"""

from __future__ import annotations

import math


def min_jerk_span(x: float, v: float, cap: float = math.inf) -> float:
    """``3 x / v`` (s): time from a minimum-jerk motion's start to a sample where it had moved
    ``x`` (m) at speed ``v`` (m/s), or from such a sample to its stop; at most ``cap``, and 0
    when ``x`` or ``v`` is not a finite positive number."""
    if not (math.isfinite(x) and math.isfinite(v)) or x <= 0.0 or v <= 1e-6:
        return 0.0
    return min(3.0 * x / v, cap)
