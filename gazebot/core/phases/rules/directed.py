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
with the one minimum-jerk helper (:func:`~gazebot.core.phases.rules.onset.min_jerk_span`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import vector_norm
from gazebot.core.phases.rules.onset import min_jerk_span
from gazebot.core.phases.trajectory import Trajectory


class _Quadratic:
    """The least-squares design of ``x ~ c0 + c1 t + c2 t^2`` at times ``t`` (relative to the
    newest sample), shared by every fit at those times: the rule fits several signals at the
    same times, and the design matrix and its normal matrix's inverse are the same for all.
    The rules take theirs from :func:`_quadratic_at`, which also shares it between calls."""

    def __init__(self, t: np.ndarray) -> None:
        n = t.shape[0]
        m = np.empty((n, 3))  # the columns (1, t, t^2), as np.stack would lay them out
        m[:, 0] = 1.0
        m[:, 1] = t
        m[:, 2] = t * t
        self.m = m
        # (x, v, a) at t = 0, and x(0) - x(t[0]): the travel within the window
        self.lin = np.array(
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0], [0.0, -t[0], -(t[0] ** 2)]]
        )
        m.flags.writeable = False
        self.lin.flags.writeable = False
        self._inverse: np.ndarray | None = None
        # The last fits: the signal's bytes -> its coefficients (read-only), or None. The
        # directed and the sequential rule fit the same gap signal at the same times in one
        # analysis; an identical lstsq call gives identical values, so it is made once.
        self._fits: dict[bytes, np.ndarray | None] = {}

    def coefficients(self, x: np.ndarray) -> np.ndarray | None:
        """``(c0, c1, c2)`` fitted to ``x`` (read-only); ``None`` if the design is singular."""
        key = x.tobytes()
        # (one dict read, never a test then a read: another thread's clear() may run between)
        known = self._fits.get(key, _UNFITTED)
        if known is not _UNFITTED:
            return known  # type: ignore[return-value]
        coef, _, rank, _ = np.linalg.lstsq(self.m, x, rcond=None)
        out = None if rank < 3 else coef
        if out is not None:
            out.flags.writeable = False
        if len(self._fits) >= _FITS_KEPT:
            self._fits.clear()
        self._fits[key] = out
        return out

    def state(self, coef: np.ndarray) -> np.ndarray:
        """``(x, v, a)`` at ``t = 0`` and the travel ``x(0) - x(t[0])`` of the fit ``coef``."""
        return self.lin @ coef

    def errors(self, x: np.ndarray, coef: np.ndarray, noise: float) -> np.ndarray:
        """The standard errors of :meth:`state` from the larger of the noise floor ``noise``
        (m) and the fit's own residuals (a motion the model does not follow)."""
        m = self.m
        n = m.shape[0]
        res = x - m @ coef
        var = max(noise * noise, float(res @ res) / max(n - 3, 1))
        if self._inverse is None:
            inverse = np.linalg.inv(m.T @ m)
            inverse.flags.writeable = False
            self._inverse = inverse
        cov = var * self._inverse
        lin = self.lin
        return np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", lin, cov, lin), 0.0))


# Fits a shared design remembers (a few analyses' worth: each fits at most six signals).
_FITS_KEPT = 16
_UNFITTED = object()  # (a fit can be None: singular design)


@functools.lru_cache(maxsize=16)
def _quadratic_of(t_bits: bytes) -> _Quadratic:
    """The design at the float64 times whose bytes are ``t_bits`` (see :func:`_quadratic_at`)."""
    return _Quadratic(np.frombuffer(t_bits))


def _quadratic_at(t: np.ndarray) -> _Quadratic:
    """The shared :class:`_Quadratic` of the float64 times ``t``: at a regular sample rate the
    fit windows of successive analyses hold the same relative times, bit for bit, so their
    design, its inverse and identical fits are made once. Keyed by the times' bytes: the same bits,
    the same design, so the same values as a fresh one."""
    return _quadratic_of(np.ascontiguousarray(t, dtype=float).tobytes())


def noise_floor(x: np.ndarray) -> float:
    """Marker noise (m, standard deviation per axis) of positions ``x`` (N, 3): the robust
    spread of their second differences (``sqrt 6`` sigma for white noise; a smooth motion adds
    little at tracking rates, and the median ignores a fidget)."""
    if x.shape[0] < 4:
        return 0.0
    d2 = np.diff(x, n=2, axis=0).reshape(-1)
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    return 1.4826 * mad / math.sqrt(6.0)


def _seen(traj: Trajectory, after: float, lo: int) -> np.ndarray:
    """The indices, from ``lo`` on, of ``traj``'s samples with both hands seen after ``after``."""
    t, g, r = traj.t, traj.giver_hand, traj.receiver_hand
    ok = np.isfinite(g[lo:]).all(axis=1) & np.isfinite(r[lo:]).all(axis=1) & (t[lo:] > after)
    return lo + ok.nonzero()[0]


def directed_reach(traj: Trajectory, c: PhaseConfig, after: float) -> float | None:
    """The back-dated onset of a reach the giver's hand shows toward the receiver at the newest
    sample of ``traj`` (times increasing, as the online window's do; see the module
    docstring), ``None`` if it shows none. Only samples after ``after`` (s) are read (the
    previous handover's end)."""
    t_all = traj.t
    n = t_all.shape[0]
    if n < c.predict_min_samples + 2:
        return None
    g, r = traj.giver_hand, traj.receiver_hand
    now = float(t_all[-1])
    # The windows below reach back from the fit window's start (predict_window, or further at
    # low rates) over the longer of predict_rest_window and predict_noise_window: the samples
    # before that (most of a long idle window) are not read unless the fit window widens past
    # it, or too few samples are seen after it (then all are).
    back = max(c.predict_rest_window, c.predict_noise_window)
    lo = int(t_all.searchsorted(now - c.predict_window - back))
    idx = _seen(traj, after, lo)
    if idx.size == 0 or idx[-1] != n - 1:
        return None  # both hands seen now: the model is not extrapolated across a dropout
    if lo:
        w0 = math.nan
        if idx.size >= c.predict_min_samples + 2:
            w0 = min(now - c.predict_window, float(t_all[idx[-c.predict_min_samples]]))
        edge = float(t_all[lo - 1])  # the newest sample skipped
        if not (
            edge < w0 - 1e-9
            and edge < w0 - c.predict_rest_window
            and edge < w0 - c.predict_noise_window
        ):
            lo = 0
            idx = _seen(traj, after, 0)
    if idx.size < c.predict_min_samples + 2:
        return None
    tv = t_all[idx]
    # The fit window: predict_window, widened to predict_min_samples at low rates.
    w0 = min(now - c.predict_window, float(tv[-c.predict_min_samples]))
    fit = idx[tv >= w0 - 1e-9]
    rest = idx[(tv < w0 - 1e-9) & (tv >= w0 - c.predict_rest_window)]
    if fit.size < c.predict_min_samples or rest.size == 0:
        return None
    t_fit = t_all[fit]
    steps = np.diff(t_fit)
    if float(steps.max()) > c.predict_gap_factor * float(np.median(steps)):
        return None  # a dropout inside the window leaves the model unconstrained there
    # The line from the giver's resting hand to the receiver's hand now.
    g_rest = g[rest].mean(axis=0)
    line = r[-1] - g_rest
    gap = vector_norm(line)
    if gap <= 1e-6:
        return None
    u = line / gap
    tf = t_fit - now
    q = _quadratic_at(tf)
    x_along = (g[fit] - g_rest) @ u
    coef = q.coefficients(x_along)
    if coef is None:
        return None
    _, v, a, x = q.state(coef)
    k = c.predict_sigmas
    # Each bar below is at least its floor (predict_distance, reach_onset_speed, 0): a fit
    # short of one fails whatever its errors, so those (and the noise floor) are only measured
    # for a fit past all three.
    if not (x >= c.predict_distance and v >= c.reach_onset_speed and a >= 0.0):
        return None
    hist = idx[(tv < w0 - 1e-9) & (tv >= w0 - c.predict_noise_window)]
    noise = noise_floor(g[hist])
    _, sv, sa, sx = q.errors(x_along, coef, noise)
    if not (x >= max(c.predict_distance, k * sx) and v >= max(c.reach_onset_speed, k * sv)):
        return None
    if not a >= k * sa:
        return None  # past its speed peak (or not known to be before it): a fidget may stop
    # ... and the hands' gap closing at a reach's speed (the receiver moving away, or a hand
    # adjusted sideways at arm's length, closes it slower than the hand moves)
    x_gap = -np.linalg.norm(r[fit] - g[fit], axis=1)  # (the fit is of minus the distance)
    coef_gap = q.coefficients(x_gap)
    if coef_gap is None:
        return None
    minus_d, v_c, a_c, closed = q.state(coef_gap)
    if not v_c >= c.reach_onset_speed:
        return None  # short of the bar's floor, whatever the error
    if not v_c >= max(c.reach_onset_speed, k * q.errors(x_gap, coef_gap, noise)[1]):
        return None
    # The model's prediction: over the next predict_horizon the hands close a share of the gap
    # they started from (a hand adjusted at arm's length closes a few cm of a metre).
    h = c.predict_horizon
    ahead = closed + v_c * h + 0.5 * max(a_c, 0.0) * h * h
    if not ahead >= c.predict_gap_share * (closed - minus_d):
        return None
    # Within acos(predict_cos) of the line: the velocity's other components, fitted alike
    # (only their velocities are read: no errors).
    vel = np.empty(3)
    for j in range(3):
        coef_j = q.coefficients(g[fit, j])
        if coef_j is None:
            return None
        vel[j] = q.state(coef_j)[1]
    speed = vector_norm(vel)
    if not speed > 0 or v / speed < c.predict_cos:
        return None
    onset = now - min_jerk_span(x, v, c.max_refine)
    if not math.isfinite(onset):
        return None
    first = tv[0] if lo == 0 else t_all[_seen(traj, after, 0)[0]]  # the first sample seen
    return max(onset, float(first), after)
