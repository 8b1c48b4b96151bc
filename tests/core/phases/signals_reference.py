"""The straightforward (whole-window, one hand at a time) signal pipeline the fast
:func:`gazebot.core.phases.filtering.compute_signals` must equal bit for bit: frozen samples out,
resample, Gaussian smoothing and central differences, as gazebot computed them before the
pipeline was fused (issue 19). Tests only."""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter1d

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import FULL_WINDOW, HAND_ACCELERATION, Signals
from gazebot.core.phases.trajectory import Trajectory


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


def drop_glitches(t: np.ndarray, p: np.ndarray, jump: float) -> np.ndarray:
    """``p`` with one-sample glitches set to NaN, one sample at a time in time order: a valid
    sample farther from the last valid one than ``jump`` + speed x dt + HAND_ACCELERATION x
    dt^2 / 2 (speed: between the two valid samples before), unless the one before was such a
    glitch and this one is within that bar of it (a step: kept, speed measured afresh)."""
    out = p.copy()
    if jump <= 0:
        return out
    last = prev = flagged = -1
    for i in range(p.shape[0]):
        if not np.isfinite(p[i]).all():
            continue
        if last < 0:
            last = i
            continue
        speed = 0.0
        if prev >= 0 and t[last] > t[prev]:
            speed = float(np.linalg.norm(p[last] - p[prev]) / (t[last] - t[prev]))

        def bar(dt: float, speed: float = speed) -> float:
            return jump + speed * dt + 0.5 * HAND_ACCELERATION * dt * dt

        if np.linalg.norm(p[i] - p[last]) <= bar(t[i] - t[last]):
            prev, last, flagged = last, i, -1
        elif flagged >= 0 and np.linalg.norm(p[i] - p[flagged]) <= bar(t[i] - t[flagged]):
            prev, last, flagged = -1, i, -1
        else:
            out[i] = np.nan
            flagged = i
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


def reference_signals(trajectory: Trajectory, config: PhaseConfig) -> Signals:
    """Frozen samples out, resample, smooth and differentiate the hands of ``trajectory``
    (sorted by time, see :meth:`Trajectory.cleaned`)."""
    t = trajectory.t
    dt = 1.0 / config.analysis_rate
    grid = t.copy() if t.shape[0] < 2 else np.arange(t[0], t[-1] + 0.5 * dt, dt)
    g = drop_frozen(t, trajectory.giver_hand, config.frozen_speed)
    r = drop_frozen(t, trajectory.receiver_hand, config.frozen_speed)
    g = drop_glitches(t, g, config.glitch_jump)
    r = drop_glitches(t, r, config.glitch_jump)
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
