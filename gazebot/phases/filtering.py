"""Filtering: from raw samples to the smooth signals every rule reads.

1. Frozen samples: a tracker that loses a marker often repeats its last position. A sample
   equal to the previous one while the hand was moving (faster than ``frozen_speed``) is stale
   and counts as missing (a resting hand may repeat its position: that is kept).
2. Resampling onto a uniform grid (``analysis_rate``), bridging gaps up to ``max_gap_hold``
   (longer gaps stay unknown, NaN).
3. Zero-lag Gaussian smoothing (``smoothing``, never narrower than two input samples) and
   velocities by central differences, unknown next to a tracking gap (where the window is
   one-sided and would flatten the motion into a false rest).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter1d

from gazebot.phases.config import PhaseConfig
from gazebot.phases.trajectory import Trajectory

# Share of the smoothing window that must hold data for a velocity to be known.
FULL_WINDOW = 0.6


@dataclass(frozen=True)
class Signals:
    """The smoothed signals the rules work on (uniform grid, NaN where unknown).

    Attributes:
        t: Grid times (N,) s.
        giver: Giver hand positions (N, 3) m.
        receiver: Receiver hand positions (N, 3) m.
        giver_v: Giver hand velocities (N, 3) m/s.
        receiver_v: Receiver hand velocities (N, 3) m/s.
        rel: Relative position receiver - giver (N, 3) m.
        rel_v: Relative velocity (N, 3) m/s.
        distance: Hands' distance (N,) m.
        rel_speed: Relative speed (N,) m/s.
        giver_speed: Giver hand speed (N,) m/s.
        receiver_speed: Receiver hand speed (N,) m/s.
        closing: Closing speed, ``-d distance / dt`` (N,) m/s: positive while the hands close.
        common_speed: Speed of the hands' midpoint (N,) m/s: their common motion.
        hold_speed: Relative speed judged against the common motion (N,) m/s: the relative
            speed in excess of the speed both hands share (the slower hand's), never below
            the closing speed's magnitude. Hands carrying an object together while the pair
            turns (the marker frames behind the hands swing with it at a constant distance)
            read slow; an approach or a separation (the distance changing), or one hand moving
            past the other, reads at its full speed.
    """

    t: np.ndarray
    giver: np.ndarray
    receiver: np.ndarray
    giver_v: np.ndarray
    receiver_v: np.ndarray
    rel: np.ndarray
    rel_v: np.ndarray
    distance: np.ndarray
    rel_speed: np.ndarray
    giver_speed: np.ndarray
    receiver_speed: np.ndarray
    closing: np.ndarray
    common_speed: np.ndarray
    hold_speed: np.ndarray

    @property
    def dt(self) -> float:
        """Grid step (s)."""
        return float(self.t[1] - self.t[0]) if self.t.shape[0] > 1 else 0.0


def drop_frozen(t: np.ndarray, p: np.ndarray, moving_speed: float) -> np.ndarray:
    """``p`` with stale repeats set to NaN: a sample exactly equal to the previous valid one,
    while the hand moved faster than ``moving_speed`` between the two valid samples before."""
    out = p.copy()
    ok = np.flatnonzero(np.isfinite(p).all(axis=1))
    if ok.size < 3:
        return out
    same = np.all(p[ok[1:]] == p[ok[:-1]], axis=1)
    if not same.any():
        return out
    last_fresh = -1  # index into ok of the last sample that was not a repeat
    prev_fresh = -1
    for k in range(1, ok.size):
        if not same[k - 1]:
            prev_fresh, last_fresh = last_fresh, k
            continue
        if last_fresh < 0 or prev_fresh < 0:
            continue
        i0, i1 = ok[prev_fresh], ok[last_fresh]
        dt = t[i1] - t[i0]
        v = float(np.linalg.norm(p[i1] - p[i0]) / dt) if dt > 0 else 0.0
        if v > moving_speed:
            out[ok[k]] = np.nan
    return out


def resample(t: np.ndarray, p: np.ndarray, grid: np.ndarray, max_gap: float) -> np.ndarray:
    """Linear interpolation of the valid rows of ``p`` onto ``grid``; NaN inside long gaps."""
    ok = np.isfinite(p).all(axis=1)
    out = np.full((grid.shape[0], 3), np.nan)
    if np.count_nonzero(ok) < 2:
        return out
    tv, pv = t[ok], p[ok]
    for k in range(3):
        out[:, k] = np.interp(grid, tv, pv[:, k])
    j = np.searchsorted(tv, grid, side="right")
    inside = (j > 0) & (j < tv.shape[0])
    gap = np.full(grid.shape[0], np.inf)
    gap[inside] = tv[j[inside]] - tv[j[inside] - 1]
    # grid points that are samples (both sorted: a searchsorted, not np.isin's sort)
    k = np.minimum(np.searchsorted(tv, grid), tv.shape[0] - 1)
    exact = tv[k] == grid
    out[(gap > max_gap + 1e-9) & ~exact] = np.nan
    return out


def _gauss(x: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian smoothing along axis 0, edges padded with the end values (scipy.ndimage)."""
    return gaussian_filter1d(x, sigma, axis=0, mode="nearest", truncate=3.0)


def smooth(x: np.ndarray, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """NaN-aware Gaussian smoothing along axis 0 (normalised convolution), zero lag.

    Returns the smoothed rows and, per row, the share of the smoothing window that held data
    (1 away from tracking gaps)."""
    m = np.isfinite(x).all(axis=1)
    if sigma <= 0 or x.shape[0] < 2:
        return x, m.astype(float)
    num = _gauss(np.where(m[:, None], x, 0.0), sigma)
    den = _gauss(m.astype(float), sigma)
    out = num / np.maximum(den, 1e-12)[:, None]
    out[(den < 0.5) | ~m] = np.nan  # do not invent samples inside long gaps
    return out, den


def compute_signals(trajectory: Trajectory, config: PhaseConfig) -> Signals:
    """Frozen samples out, resample, smooth and differentiate the hands of ``trajectory``
    (sorted by time, see :meth:`Trajectory.cleaned`)."""
    t = trajectory.t
    dt = 1.0 / config.analysis_rate
    grid = t.copy() if t.shape[0] < 2 else np.arange(t[0], t[-1] + 0.5 * dt, dt)
    g = drop_frozen(t, trajectory.giver_hand, config.frozen_speed)
    r = drop_frozen(t, trajectory.receiver_hand, config.frozen_speed)
    g = resample(t, g, grid, config.max_gap_hold)
    r = resample(t, r, grid, config.max_gap_hold)
    # Smooth at least over a couple of input samples: 8 Hz data interpolated to 100 Hz has
    # corners at every sample that would otherwise show up as speed spikes.
    med_dt = float(np.median(np.diff(t))) if t.shape[0] > 1 else dt
    sigma_s = max(0.5 * config.smoothing, 0.5 * med_dt)
    g, g_full = smooth(g, sigma_s / dt)
    r, r_full = smooth(r, sigma_s / dt)
    if grid.shape[0] >= 2:
        gv = np.gradient(g, dt, axis=0)
        rv = np.gradient(r, dt, axis=0)
        # Next to a tracking gap the window is one-sided and flattens the motion: velocities
        # there are unknown, not slow.
        gv[g_full < FULL_WINDOW] = np.nan
        rv[r_full < FULL_WINDOW] = np.nan
    else:
        gv = np.full_like(g, np.nan)
        rv = np.full_like(r, np.nan)
    rel = r - g
    rel_v = rv - gv
    distance = np.linalg.norm(rel, axis=1)
    rel_speed = np.linalg.norm(rel_v, axis=1)
    closing = -np.einsum("ij,ij->i", rel_v, rel) / np.maximum(distance, 1e-9)
    common = 0.5 * np.linalg.norm(gv + rv, axis=1)
    g_speed = np.linalg.norm(gv, axis=1)
    r_speed = np.linalg.norm(rv, axis=1)
    return Signals(
        t=grid,
        giver=g,
        receiver=r,
        giver_v=gv,
        receiver_v=rv,
        rel=rel,
        rel_v=rel_v,
        distance=distance,
        rel_speed=rel_speed,
        giver_speed=g_speed,
        receiver_speed=r_speed,
        closing=closing,
        common_speed=common,
        hold_speed=np.maximum(np.abs(closing), rel_speed - np.minimum(g_speed, r_speed)),
    )
