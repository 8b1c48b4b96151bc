"""Idle -> reach, predictive (online): a sequential likelihood-ratio test on the giver's hand.

A reach and a fidget start alike: near its start every minimum-jerk motion covers ``k (t -
t0)^3``, whatever its size, so the first few centimetres cannot tell a 2 cm adjustment from a
40 cm reach. What does tell them apart is how long the cubic growth goes on: a fidget's
profile bends over at its midpoint, a reach's keeps growing. The rule therefore compares two
classes of motion, each a minimum-jerk motion from rest (the seed's local linear model of the
hand, eq. 4.5, in its minimum-jerk form) with onset ``t0`` within the last
``sequential_onset_span`` and duration ``T`` within ``sequential_durations``:

- a *fidget* (or rest, or sway): amplitude at most ``fidget_amplitude`` (1-2 cm adjustments);
- a *reach*: amplitude at least ``min_approach`` (any reach closes 10 cm).

For each ``(t0, T)`` on a grid, the best amplitude vector (3-D, with a free rest position) is a
least-squares fit in closed form, clipped to the class's bound. The statistic is the
generalised likelihood ratio ``(RSS_fidget - RSS_reach) / sigma^2``: the sum of squared
residuals the best fidget leaves beyond the best reach, in units of the noise variance
``sigma^2`` (the larger of the marker noise measured before the window, :func:`noise_floor`,
and the reach fit's own residual, and at least the grids' resolution: the onset grid misplaces
a moving hand by up to half a step times its speed). A reach is confirmed when it reaches
``sequential_evidence``.
Because the statistic sums over the samples in units of the measured noise, its bar scales
with the sample rate and the noise floor by construction: more samples or less noise confirm
sooner, sparse or noisy samples later; no travel distance or speed is fixed. The only
distances are the two classes' bounds, which are properties of human motion, not of the
tracker.

Further, the fitted reach must head toward the receiver (within ``acos(predict_cos)`` of the
line from its rest position to the receiver's hand) and the hands' gap must be closing at a
reach's pace: a constant-acceleration fit of the gap over the last ``predict_window``
closes ``predict_gap_share`` of the starting gap within ``predict_horizon`` (a hand adjusted
sideways at arm's length, or a receiver moving away, does not). The onset is the fitted
reach's ``t0``.

It runs beside the constant-acceleration rule (:mod:`~gazebot.core.phases.rules.directed`), whose
bars are fixed at their floors (1.6 cm of travel, 15 cm/s); the method takes whichever
confirms first.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from gazebot.core.minimum_jerk import minimum_jerk
from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import vector_norm
from gazebot.core.phases.rules.directed import _quadratic_at, noise_floor
from gazebot.core.phases.trajectory import Trajectory


@dataclass(frozen=True)
class ReachEvidence:
    """The test's outcome at one sample.

    Attributes:
        statistic: ``(RSS_fidget - RSS_reach) / sigma^2`` (1): how much better a reach
            explains the window than any fidget.
        onset: The best reach's start ``t0`` (s).
        duration: ... its duration ``T`` (s).
        amplitude: ... its amplitude vector (m, 3).
        rest: ... the hand's rest position before it (m, 3).
        sigma: The noise used (m, per axis).
    """

    statistic: float
    onset: float
    duration: float
    amplitude: np.ndarray
    rest: np.ndarray
    sigma: float


def _best_reduction(
    norm: np.ndarray, b: np.ndarray, ratio: np.ndarray, lo: float, hi: float
) -> tuple[np.ndarray, np.ndarray]:
    """The largest drop of the residual sum of squares ``2 m |S| - m^2 B`` over amplitudes
    ``m`` in ``[lo, hi]`` (``norm``: ``|S|``, the template-data products' norms; ``b``: ``B``,
    the template energy; ``ratio``: ``|S| / max(B, 1e-12)``, the unbounded best ``m``, shared
    by both classes), and that ``m``."""
    m = np.clip(ratio, lo, hi)
    return 2.0 * m * norm - m * m * b, m


def _binned(t: np.ndarray, x: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Samples averaged per ``step`` (s) bin: (mean times, mean positions, counts). The
    templates are smooth on that scale, so the test loses nothing; at 240 Hz it reads a
    third as many rows."""
    key = np.floor((t - t[0]) / step).astype(np.int64)
    cuts = (key[1:] != key[:-1]).nonzero()[0]
    bounds = np.empty(cuts.shape[0] + 2, dtype=np.int64)  # 0, the cuts, n
    bounds[0] = 0
    np.add(cuts, 1, out=bounds[1:-1])
    bounds[-1] = t.shape[0]
    counts = (bounds[1:] - bounds[:-1]).astype(float)
    starts = bounds[:-1]
    tb = np.add.reduceat(t, starts) / counts
    xb = np.add.reduceat(x, starts, axis=0) / counts[:, None]
    return tb, xb, counts


@functools.lru_cache(maxsize=8)
def _grids(
    durations: tuple[float, float], steps: int, span: float, step: float
) -> tuple[np.ndarray, np.ndarray]:
    """The test's grids, which depend on the configuration alone (computed once per
    configuration): ``steps`` geometric durations (s) over ``durations`` and the onsets' lags
    (s) before the newest sample, ``0, step, ...`` short of ``span``. Read-only."""
    lo, hi = durations
    grid = np.geomspace(lo, hi, steps)
    lags = np.arange(0.0, span, step)
    grid.flags.writeable = False
    lags.flags.writeable = False
    return grid, lags


def reach_evidence(
    t: np.ndarray, x: np.ndarray, now: float, noise: float, c: PhaseConfig
) -> ReachEvidence | None:
    """The likelihood-ratio test of the module docstring on samples ``x`` (N, 3) at times
    ``t`` (s, all finite, ending at ``now``), marker noise ``noise`` (m); ``None`` if the
    samples cannot carry it (fewer than ``predict_min_samples``)."""
    n = t.shape[0]
    if n < c.predict_min_samples:
        return None
    durations, lags = _grids(
        c.sequential_durations,
        c.sequential_duration_steps,
        c.sequential_onset_span,
        c.sequential_onset_step,
    )
    onsets = now - lags
    tb, xb, w = _binned(t, x, 0.5 * c.sequential_onset_step)
    mean_x = w @ xb / n
    xc = xb - mean_x
    # templates (onset, duration, bin), centred (weighted): the rest position is free
    tmpl = minimum_jerk((tb[None, None, :] - onsets[:, None, None]) / durations[None, :, None])
    mean_b = tmpl @ w / n
    tmpl -= mean_b[..., None]
    wt = tmpl * w
    energy = np.einsum("abn,abn->ab", wt, tmpl)
    prod = wt @ xc  # (onset, duration, 3)
    norms = np.linalg.norm(prod, axis=-1)
    ratio = norms / np.maximum(energy, 1e-12)
    reach, m_reach = _best_reduction(norms, energy, ratio, c.min_approach, math.inf)
    fidget, _ = _best_reduction(norms, energy, ratio, 0.0, c.fidget_amplitude)
    k = divmod(int(reach.argmax()), reach.shape[1])
    best_fidget = float(fidget.max())
    dx = x - mean_x
    rss0 = float(np.einsum("ij,ij->", dx, dx))
    dof = max(3 * n - 7, 1)
    norm = vector_norm(prod[k])
    amp = m_reach[k] * prod[k] / norm if norm > 0 else np.zeros(3)
    # The grids' own resolution: an onset off by half a step misplaces a motion moving at
    # speed v by up to v step / 2 (uniform: / sqrt 3), noise or not (with none, the fits'
    # tiny misfits alone would otherwise decide).
    s_now = min((now - float(onsets[k[0]])) / float(durations[k[1]]), 1.0)
    speed = vector_norm(amp) * 30.0 * s_now**2 * (1.0 - s_now) ** 2 / durations[k[1]]
    grid = speed * 0.5 * c.sequential_onset_step
    sigma2 = max(noise * noise, (rss0 - float(reach[k])) / dof, grid * grid / 3.0, 1e-12)
    rest = mean_x - amp * mean_b[k]
    return ReachEvidence(
        (float(reach[k]) - best_fidget) / sigma2,
        float(onsets[k[0]]),
        float(durations[k[1]]),
        amp,
        rest,
        math.sqrt(sigma2),
    )


def sequential_reach(
    traj: Trajectory, c: PhaseConfig, after: float, evidence: float | None = None
) -> float | None:
    """The onset of a reach the giver's hand shows toward the receiver at the newest sample of
    ``traj`` (see the module docstring), ``None`` if it shows none. Only samples after
    ``after`` (s) are read (the previous handover's end). ``evidence``: the bar of the
    statistic (default ``sequential_evidence``)."""
    bar = c.sequential_evidence if evidence is None else evidence
    t_all = traj.t
    if t_all.shape[0] < c.predict_min_samples + 2:
        return None
    g, r = traj.giver_hand, traj.receiver_hand
    now = float(t_all[-1])
    lo = int(t_all.searchsorted(max(now - c.sequential_window - c.predict_noise_window, after)))
    ok = np.isfinite(g[lo:]).all(axis=1) & np.isfinite(r[lo:]).all(axis=1) & (t_all[lo:] > after)
    if ok.size == 0 or not ok[-1]:
        # Both hands seen now, after ``after``: the model is not extrapolated across a
        # dropout (none at all: ``after`` is the newest sample, a handover just ended).
        return None
    idx = lo + ok.nonzero()[0]
    tv = t_all[idx]
    win = idx[tv > now - c.sequential_window]
    if win.size < c.predict_min_samples:
        return None
    # A fidget fits any cubic start up to its midpoint: a hand not yet half the largest fidget
    # from its rest (the window before every onset tried), or not toward the receiver, cannot
    # be told from one (cheap skips before the test; first, as a hand at rest fails them).
    tw = t_all[win]
    rest = win[tw <= now - c.sequential_onset_span]
    last = win[tw >= now - 0.5 * c.sequential_onset_step]
    if rest.size:
        g_rest = g[rest].mean(axis=0)
        moved = g[last].mean(axis=0) - g_rest
        toward = float(moved @ (r[-1] - g_rest))
        if vector_norm(moved) < 0.5 * c.fidget_amplitude or toward <= 0.0:
            return None
    # A dropout only matters where the gap's closing is fitted (the last predict_window): the
    # templates are whole minimum-jerk motions, fitted to the samples there are, so a gap
    # earlier in the window leaves them constrained (it used to suspend the test for 0.8 s).
    steps = np.diff(tw)
    recent = tw[1:] >= now - c.predict_window
    step = float(np.median(steps))
    if recent.any() and float(steps[recent].max()) > c.predict_gap_factor * step:
        return None
    # The hands' gap closing at a reach's pace (the receiver moving away, or a hand adjusted
    # sideways at arm's length, closes it slower than the hand moves): a constant-acceleration
    # model of the gap closes faster than predict_sigmas of its standard error ...
    w0 = min(now - c.predict_window, float(tw[-c.predict_min_samples]))
    fit = win[tw >= w0]
    q = _quadratic_at(t_all[fit] - now)
    x_gap = -np.linalg.norm(r[fit] - g[fit], axis=1)
    coef = q.coefficients(x_gap)
    if coef is None:
        return None
    _, v_c, a_c, _ = q.state(coef)
    # (a gap not closing fails that bar whatever its error: the error, the noise floor and the
    # test are only measured for one that closes)
    if not v_c >= 0.0:
        return None
    noise = noise_floor(g[idx[tv <= now - c.sequential_window]])
    if not v_c >= c.predict_sigmas * q.errors(x_gap, coef, noise)[1]:
        return None
    ev = reach_evidence(t_all[win], g[win], now, noise, c)
    if ev is None or not ev.statistic >= bar:
        return None
    # Toward the receiver: the fitted reach within acos(predict_cos) of the line to its hand.
    line = r[-1] - ev.rest
    gap = vector_norm(line)
    amp = vector_norm(ev.amplitude)
    if gap <= 1e-6 or amp <= 0 or float(ev.amplitude @ line) < c.predict_cos * amp * gap:
        return None
    # ... and, extrapolated predict_horizon ahead, closes a share of the gap the hands started
    # from.
    h = c.predict_horizon
    closed = vector_norm(r[-1] - ev.rest) - vector_norm(r[-1] - g[-1])
    ahead = closed + v_c * h + 0.5 * max(a_c, 0.0) * h * h
    if not ahead >= c.predict_gap_share * gap:
        return None
    return max(ev.onset, float(t_all[win[0]]), after)
