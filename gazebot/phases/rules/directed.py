"""Idle -> reach, predictive (online): the giver's hand accelerating toward the receiver.

The seed predicts the human hand with a linear model fitted by least squares to the samples of
"a pre-defined time interval before the current time-step" (eq. 4.5, ``p' = A p``). Here the
model is the local one of a hand starting to move: constant acceleration along the line from
the giver's hand to the receiver's hand, ``x(t) = x0 + v t + a t^2 / 2``, fitted to the raw
samples of the last ``predict_window`` (at least ``predict_min_samples`` of them, so the window
widens at low rates; the newest sample seen, no gap in the window longer than
``predict_gap_factor`` sampling intervals). The noise floor is measured on the samples of the
``predict_noise_window`` before (:func:`noise_floor`), or is the fit's own residual if that is
larger; the fit's covariance turns it into standard errors of ``x``, ``v`` and ``a`` (more
noise or fewer samples raise them); every bar below is at least ``predict_sigmas`` of them.

A reach is confirmed when, along that line, the hand

- has moved ``predict_distance`` within the window (the travel of this motion alone, not of a
  fidget before it),
- moves faster than ``reach_onset_speed``, within ``acos(predict_cos)`` of the line,
- is still accelerating, and
- the hands' gap closes faster than ``reach_onset_speed`` (as the smoothed rule asks), and
  the model, extrapolated ``predict_horizon`` ahead, closes ``predict_gap_share`` of the gap
  the hands started from (the seed's use of eq. 4.5: where the hand goes next).

A minimum-jerk motion accelerates only during the first half of its travel, so such a hand will
go on to cover more than ``2 x predict_distance``: more than any fidget (a fidget of 1-2 cm
toward the receiver peaks in speed, and stops accelerating, halfway). The onset is back-dated
with the one minimum-jerk helper (:func:`~gazebot.phases.rules.onset.min_jerk_span`).
"""

from __future__ import annotations

import math

import numpy as np

from gazebot.phases.config import PhaseConfig
from gazebot.phases.filtering import median, vector_norm
from gazebot.phases.rules.onset import min_jerk_span
from gazebot.phases.trajectory import Trajectory


def _fit(t: np.ndarray, x: np.ndarray, noise: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Least-squares ``x ~ c0 + c1 t + c2 t^2`` (``t`` relative to the newest sample): ``(x, v,
    a)`` at ``t = 0`` and the travel ``x(0) - x(t[0])`` over the window, with their standard
    errors from the larger of the noise floor ``noise`` (m) and the fit's own residuals (a
    motion the model does not follow); ``None`` if singular."""
    n = t.shape[0]
    m = np.stack([np.ones(n), t, t * t], axis=1)
    coef, _, rank, _ = np.linalg.lstsq(m, x, rcond=None)
    if rank < 3:
        return None
    res = x - m @ coef
    var = max(noise * noise, float(res @ res) / max(n - 3, 1))
    cov = var * np.linalg.inv(m.T @ m)
    # (x, v, a) at t = 0, and x(0) - x(t[0]): the travel within the window
    lin = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0], [0.0, -t[0], -(t[0] ** 2)]])
    se = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", lin, cov, lin), 0.0))
    return lin @ coef, se


def noise_floor(x: np.ndarray) -> float:
    """Marker noise (m, standard deviation per axis) of positions ``x`` (N, 3): the robust
    spread of their second differences (``sqrt 6`` sigma for white noise; a smooth motion adds
    little at tracking rates, and the median ignores a fidget)."""
    if x.shape[0] < 4:
        return 0.0
    d2 = np.diff(x, n=2, axis=0).reshape(-1)
    mad = median(np.abs(d2 - median(d2)))
    return 1.4826 * mad / math.sqrt(6.0)


def directed_reach(traj: Trajectory, c: PhaseConfig, after: float) -> float | None:
    """The back-dated onset of a reach the giver's hand shows toward the receiver at the newest
    sample of ``traj`` (see the module docstring), ``None`` if it shows none. Only samples
    after ``after`` (s) are read (the previous handover's end)."""
    t_all = traj.t
    if t_all.shape[0] < c.predict_min_samples + 2:
        return None
    g, r = traj.giver_hand, traj.receiver_hand
    now = float(t_all[-1])
    ok = np.isfinite(g).all(axis=1) & np.isfinite(r).all(axis=1) & (t_all > after)
    idx = np.flatnonzero(ok)
    if idx.size < c.predict_min_samples + 2 or not ok[-1]:
        return None  # both hands seen now: the model is not extrapolated across a dropout
    tv = t_all[idx]
    # The fit window: predict_window, widened to predict_min_samples at low rates.
    w0 = min(now - c.predict_window, float(tv[-c.predict_min_samples]))
    fit = idx[tv >= w0 - 1e-9]
    rest = idx[(tv < w0 - 1e-9) & (tv >= w0 - c.predict_rest_window)]
    if fit.size < c.predict_min_samples or rest.size == 0:
        return None
    steps = np.diff(t_all[fit])
    if float(steps.max()) > c.predict_gap_factor * median(steps):
        return None  # a dropout inside the window leaves the model unconstrained there
    # The line from the giver's resting hand to the receiver's hand now.
    g_rest = g[rest].mean(axis=0)
    line = r[-1] - g_rest
    gap = vector_norm(line)
    if gap <= 1e-6:
        return None
    u = line / gap
    hist = idx[(tv < w0 - 1e-9) & (tv >= w0 - c.predict_noise_window)]
    noise = noise_floor(g[hist])
    tf = t_all[fit] - now
    along = _fit(tf, (g[fit] - g_rest) @ u, noise)
    if along is None:
        return None
    (_, v, a, x), (_, sv, sa, sx) = along
    k = c.predict_sigmas
    if not (x >= max(c.predict_distance, k * sx) and v >= max(c.reach_onset_speed, k * sv)):
        return None
    if not a >= k * sa:
        return None  # past its speed peak (or not known to be before it): a fidget may stop
    # ... and the hands' gap closing at a reach's speed (the receiver moving away, or a hand
    # adjusted sideways at arm's length, closes it slower than the hand moves)
    gap_fit = _fit(tf, -np.linalg.norm(r[fit] - g[fit], axis=1), noise)
    if gap_fit is None or not gap_fit[0][1] >= max(c.reach_onset_speed, k * gap_fit[1][1]):
        return None
    # The model's prediction: over the next predict_horizon the hands close a share of the gap
    # they started from (a hand adjusted at arm's length closes a few cm of a metre).
    (minus_d, v_c, a_c, closed), _ = gap_fit  # (the fit is of minus the distance)
    h = c.predict_horizon
    ahead = closed + v_c * h + 0.5 * max(a_c, 0.0) * h * h
    if not ahead >= c.predict_gap_share * (closed - minus_d):
        return None
    # Within acos(predict_cos) of the line: the velocity's other components, fitted alike.
    across = [_fit(tf, g[fit, j], noise) for j in range(3)]
    if any(f is None for f in across):
        return None
    vel = np.array([f[0][1] for f in across if f is not None])
    speed = vector_norm(vel)
    if not speed > 0 or v / speed < c.predict_cos:
        return None
    onset = now - min_jerk_span(x, v, c.max_refine)
    return max(onset, float(tv[0]), after) if math.isfinite(onset) else None
