"""A lower bound on online reach confirmation latency: when could any detector that reads the
giver's hand, and reports no reach on the generator's fidgets, have confirmed a synthetic reach?

(gazebot's reach is the giver's: the robot's own reach reaches the engine as an event. The
synthetic robot is scripted to set off 50-400 ms after the giver's true onset, so a detector
reading its gripper would measure that script, and on a robot that waits for the reported reach,
its own output.)

A fidget of the generator's class (:data:`~gazebot.core.phases.synthetic.FIDGET_AMPLITUDE`,
:data:`~gazebot.core.phases.synthetic.FIDGET_DURATION`: a minimum-jerk move of at most 2 cm in
0.25-0.6
s, in any direction, toward the receiver too) starts exactly like a reach: both grow as ``k (t -
t0)^3``. An ideal observer is given far more than a detector has: the giver's hand *as the
generator moved it* (no marker noise, no sway, no dropouts, the reach known), the recording's
noise ``sigma``, and no decision grid. It still cannot confirm the reach before the samples seen
so far differ from the best fidget (with its own rest position) by ``bar`` noise variances:

    ``min over fidgets  sum_i |x(t_i) - rest - fidget(t_i)|^2 / sigma^2  >=  bar``

Below that, a fidget explains the samples as well as the reach does, so a detector that
confirms there reports the same reach on that fidget. Every simplification errs toward an
earlier bound: the fidget's timing is searched on a grid and refined from its best point (a
fit short of the best leaves more), the samples are noise-free, and ``bar`` = 1 (one noise
variance of total separation) is far below what a detector needs to stay silent over thousands
of noisy decisions. The statistic only grows with more samples (a fit over more terms cannot
leave less), so the first sample that reaches the bar is found by bisection.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import minimize

from gazebot.core.minimum_jerk import minimum_jerk
from gazebot.core.phases.synthetic import FIDGET_AMPLITUDE, FIDGET_DURATION, SyntheticHandover

ONSET_STEP = 0.005  # s between the fidget onsets tried
DURATION_STEPS = 12  # fidget durations tried, geometric over FIDGET_DURATION
REST_BEFORE = 0.5  # s of samples before the true onset the observer reads (the hand at rest)


def _reduction(
    t: np.ndarray, xc: np.ndarray, onsets: np.ndarray, durations: np.ndarray
) -> np.ndarray:
    """Per (onset, duration): how much of the centred samples' sum of squares ``xc`` (N, 3) the
    best fidget of that timing (amplitude up to the class's, along the best direction)
    explains (m^2)."""
    tmpl = minimum_jerk((t[None, None, :] - onsets[:, None, None]) / durations[None, :, None])
    tmpl -= tmpl.mean(axis=-1, keepdims=True)  # centred: the rest position is free
    energy = np.einsum("abn,abn->ab", tmpl, tmpl)
    prod = tmpl @ xc  # (onset, duration, 3): the best direction is along it
    norm = np.linalg.norm(prod, axis=-1)
    m = np.clip(norm / np.maximum(energy, 1e-18), 0.0, FIDGET_AMPLITUDE[1])
    return 2.0 * m * norm - m * m * energy


def fidget_residual(t: np.ndarray, x: np.ndarray) -> float:
    """The least sum of squares (m^2) a rest position plus one fidget of the generator's class
    leaves on samples ``x`` (N, 3) at times ``t`` (s): a grid search over the fidget's onset
    and duration, refined from the best grid point (Nelder-Mead; the amplitude is closed
    form)."""
    now = float(t[-1])
    lo, hi = FIDGET_DURATION
    xc = x - x.mean(axis=0)
    total = float(np.einsum("ij,ij->", xc, xc))
    onsets = np.arange(float(t[0]) - hi, now + 1e-9, ONSET_STEP)
    durations = np.geomspace(lo, hi, DURATION_STEPS)
    grid = _reduction(t, xc, onsets, durations)
    a, b = np.unravel_index(int(np.argmax(grid)), grid.shape)

    def left(p: np.ndarray) -> float:
        d = float(np.clip(p[1], lo, hi))
        return total - float(_reduction(t, xc, np.array([p[0]]), np.array([d]))[0, 0])

    fine = minimize(left, [onsets[a], durations[b]], method="Nelder-Mead",
                    options={"xatol": 1e-5, "fatol": 1e-14})
    return max(min(total - float(grid[a, b]), float(fine.fun)), 0.0)


def bound_latencies(case: SyntheticHandover, bar: float = 1.0, horizon: float = 0.8) -> list[float]:
    """Per handover of ``case``: the first sample time (s after the true onset) at which its
    giver's motion is ``bar`` noise variances from every fidget (``inf`` if not within
    ``horizon`` s)."""
    t, x = case.trajectory.t, case.giver_motion
    sigma2 = max(case.options.noise, 1e-6) ** 2
    out = []
    rested = -math.inf  # the previous handover's end: its retreat is no fidget
    for h in case.truth:
        first = int(np.searchsorted(t, max(h.reach_start - REST_BEFORE, rested)))
        rested = h.retreat_end
        cand = np.flatnonzero((t > h.reach_start) & (t <= h.reach_start + horizon))

        def separated(i: int, first: int = first) -> bool:
            return fidget_residual(t[first : i + 1], x[first : i + 1]) / sigma2 >= bar

        if cand.size == 0 or not separated(int(cand[-1])):
            out.append(math.inf)
            continue
        lo, hi = 0, cand.size - 1  # the answer lies in cand[lo..hi]
        while lo < hi:
            mid = (lo + hi) // 2
            if separated(int(cand[mid])):
                hi = mid
            else:
                lo = mid + 1
        out.append(float(t[cand[lo]] - h.reach_start))
    return out
