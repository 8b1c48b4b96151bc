"""Filtering: from raw samples to the smooth signals every rule reads.

1. Frozen samples: a tracker that loses a marker often repeats its last position. A sample
   equal to the previous one while the hand was moving (faster than ``frozen_speed``) is stale
   and counts as missing (a resting hand may repeat its position: that is kept).
   A one-sample glitch (a marker swapped for a frame: 1.5-7 cm on a mocap suit, issue 33), a
   sample farther than ``glitch_jump`` beyond where the hand's last speed could take it from
   the last valid sample, counts as missing too; a sample that stays near it is a real step
   of the marker and is kept from there on. Both are decided in time order, from the samples
   before only (online, the newest sample is judged at once).
2. Resampling onto a uniform grid (``analysis_rate``), bridging gaps up to ``max_gap_hold``
   (longer gaps stay unknown, NaN).
3. Zero-lag Gaussian smoothing (``smoothing``, never narrower than two input samples) and
   velocities by central differences, unknown next to a tracking gap (where the window is
   one-sided and would flatten the motion into a false rest).

Both hands go through each step together (one array of six columns). The result is, bit for
bit, what the steps give one hand at a time (``tests/core/phases/signals_reference.py`` keeps
that form and the tests compare the two). Online, a :class:`SignalCache` keeps the last result,
and the next analysis of the same window a few samples longer computes only the rows those
samples change (the same result, bit for bit).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.ndimage import correlate1d, gaussian_filter1d

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.trajectory import Trajectory

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


def drop_frozen(t: np.ndarray, p: np.ndarray, moving_speed: float, ok: np.ndarray) -> np.ndarray:
    """Which rows of ``p`` are stale repeats (a bool mask): a sample exactly equal to the
    previous valid one (``ok``: the valid rows), while the hand moved faster than
    ``moving_speed`` between the two valid samples before."""
    stale = np.zeros(p.shape[0], dtype=bool)
    idx = ok.nonzero()[0]
    if idx.size < 3:
        return stale
    pv = p[idx]
    same = (pv[1:] == pv[:-1]).all(axis=1)
    if not same.any():
        return stale
    last_fresh = -1  # index into idx of the last sample that was not a repeat
    prev_fresh = -1
    for k, rep in enumerate(same.tolist(), start=1):
        if not rep:
            prev_fresh, last_fresh = last_fresh, k
            continue
        if last_fresh < 0 or prev_fresh < 0:
            continue
        i0, i1 = idx[prev_fresh], idx[last_fresh]
        dt = t[i1] - t[i0]
        v = vector_norm(p[i1] - p[i0]) / dt if dt > 0 else 0.0
        if v > moving_speed:
            stale[idx[k]] = True
    return stale


#: The most a hand accelerates (m/s^2; reaching peaks at 5-15): the part of a glitch's bar
#: that grows with the sample interval (7 cm at 8 Hz, 1 cm at 30 Hz, 0.7 mm at 120 Hz).
HAND_ACCELERATION = 20.0


def drop_glitches(t: np.ndarray, p: np.ndarray, jump: float, ok: np.ndarray) -> np.ndarray:
    """Which rows of ``p`` are one-sample glitches (a bool mask) among the valid rows ``ok``:
    farther from the last valid sample than ``jump`` plus where the hand could have gone in the
    interval ``dt`` (its speed between the two valid samples before times ``dt``, plus
    :data:`HAND_ACCELERATION` ``dt^2 / 2``), unless the sample before was such a glitch and
    this one lies within that bar of it (the marker really moved: kept, and the speed is
    measured afresh from there). ``jump`` <= 0: none."""
    bad = np.zeros(p.shape[0], dtype=bool)
    idx = ok.nonzero()[0]
    if not jump > 0 or idx.size < 2:
        return bad
    pv = p[idx]
    if not (np.linalg.norm(pv[1:] - pv[:-1], axis=1) > jump).any():
        return bad  # (no step beyond the bar's least value: no glitch)
    def bar(speed: float, dt: float) -> float:
        return jump + speed * dt + 0.5 * HAND_ACCELERATION * dt * dt

    last, prev, flagged = int(idx[0]), -1, -1
    for i in idx[1:].tolist():
        speed = 0.0
        if prev >= 0 and t[last] > t[prev]:
            speed = vector_norm(p[last] - p[prev]) / float(t[last] - t[prev])
        if vector_norm(p[i] - p[last]) <= bar(speed, float(t[i] - t[last])):
            prev, last, flagged = last, i, -1
        elif flagged >= 0 and vector_norm(p[i] - p[flagged]) <= bar(
            speed, float(t[i] - t[flagged])
        ):
            prev, last, flagged = -1, i, -1  # a step: kept from here on
        else:
            bad[i] = True
            flagged = i
    return bad


def _steps_beyond(rows: np.ndarray, jump: float) -> bool:
    """Whether any hand's position (rows: N x 6, both hands) moves more than ``jump`` from one
    row to the next (NaN rows never do)."""
    if not jump > 0 or rows.shape[0] < 2:
        return False
    d = (rows[1:] - rows[:-1]).reshape(rows.shape[0] - 1, 2, 3)
    with np.errstate(invalid="ignore"):
        return bool((np.einsum("ijk,ijk->ij", d, d) > jump * jump).any())


def _far_from_samples(tv: np.ndarray, grid: np.ndarray, bar: float) -> np.ndarray:
    """Grid points inside a gap longer than ``bar`` between the valid sample times ``tv`` (or
    outside them), unless the point is a sample itself."""
    j = tv.searchsorted(grid, side="right")
    gap = np.full(grid.shape[0], np.inf)
    inside = (j > 0) & (j < tv.shape[0])
    ji = j[inside]
    gap[inside] = tv[ji] - tv[ji - 1]
    # grid points that are samples (both sorted: a searchsorted, not np.isin's sort)
    k = np.minimum(tv.searchsorted(grid), tv.shape[0] - 1)
    return (gap > bar) & (tv[k] != grid)


def resample(
    t: np.ndarray, p: np.ndarray, ok: np.ndarray | None, grid: np.ndarray, max_gap: float
) -> np.ndarray:
    """Linear interpolation of the valid rows (``ok``; ``None``: all) of ``p`` (N, 3 or 6: two
    hands that share ``ok``) onto ``grid``; NaN inside gaps longer than ``max_gap``."""
    out = np.empty((grid.shape[0], p.shape[1]))  # (every column is written below)
    tv, pv = (t, p) if ok is None else (t[ok], p[ok])
    if tv.shape[0] < 2:
        out.fill(np.nan)
        return out
    for k in range(p.shape[1]):
        out[:, k] = np.interp(grid, tv, pv[:, k])
    bar = max_gap + 1e-9
    if float((tv[1:] - tv[:-1]).max()) <= bar:
        # No gap between the samples is that long (the usual case): only the grid points
        # before the first sample or after the last one are far from them.
        out[: int(grid.searchsorted(tv[0], side="left"))] = np.nan
        out[int(grid.searchsorted(tv[-1], side="right")) :] = np.nan
    else:
        out[_far_from_samples(tv, grid, bar)] = np.nan
    return out


@lru_cache(maxsize=16)
def _seen_share(sigma: float) -> float:
    """The smoothed "seen" mask of a hand seen at every row: the same value everywhere (the
    filter sums the same products at each row), computed once per ``sigma``."""
    return float(correlate1d(np.ones(1), gaussian_weights(sigma), mode="nearest")[0])


@lru_cache(maxsize=16)
def gaussian_weights(sigma: float) -> np.ndarray:
    """The weights ``scipy.ndimage.gaussian_filter1d(x, sigma, truncate=3.0)`` correlates with
    (its response to a unit impulse: a sum of one product and zeros, so exactly its weights),
    computed once per ``sigma``."""
    radius = int(3.0 * float(sigma) + 0.5)
    impulse = np.zeros(2 * radius + 1)
    impulse[radius] = 1.0
    w = gaussian_filter1d(impulse, sigma, mode="nearest", truncate=3.0)
    w.setflags(write=False)
    return w


def smooth(x: np.ndarray, m: np.ndarray, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """NaN-aware Gaussian smoothing along axis 0 (normalised convolution), zero lag, edges
    padded with the end values. ``x`` holds one hand per three columns, ``m`` (N, hands) which
    rows of each hand hold data.

    Returns the smoothed rows and, per row and hand, the share of the smoothing window that
    held data (1 away from tracking gaps)."""
    hands = m.shape[1]
    if sigma <= 0 or x.shape[0] < 2:
        return x, m.astype(float)
    rows = x.shape[0]
    if m.all():
        return _smooth_all_seen(x, hands, sigma)
    w = gaussian_weights(sigma)
    # per row and hand: x, y, z (0 where unseen) and whether seen; smoothed in one call
    stack = np.empty((rows, hands, 4))
    stack[:, :, :3] = np.where(m[:, :, None], x.reshape(rows, hands, 3), 0.0)
    stack[:, :, 3] = m
    both = np.empty_like(stack)
    correlate1d(stack, w, axis=0, output=both, mode="nearest")
    den = both[:, :, 3]
    out = both[:, :, :3] / np.maximum(den, 1e-12)[:, :, None]
    out[(den < 0.5) | ~m] = np.nan  # do not invent samples inside long gaps
    return out.reshape(rows, 3 * hands), den


def _smooth_all_seen(x: np.ndarray, hands: int, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`smooth` of at least two rows, every one seen (only the positions need
    smoothing; the seen share is the same at every row), ``sigma`` > 0."""
    share = _seen_share(sigma)
    den = np.full((x.shape[0], hands), share)
    out = correlate1d(x, gaussian_weights(sigma), axis=0, mode="nearest")
    out /= max(share, 1e-12)
    if share < 0.5:
        out[:] = np.nan
    return out, den


@lru_cache(maxsize=64)
def _prefix_shares(rows: int, seen: int, sigma: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What :func:`smooth`'s masked path derives from a mask of ``rows`` rows whose first
    ``seen`` are seen (both hands), which depends on those three numbers alone (computed once
    per triple: the online cache asks for the same few again and again): the window's seen
    share per row and hand (rows, 2; smooth's ``den``, the same correlation of the same
    line), its divisor ``max(share, 1e-12)`` per column (rows, 6) and which columns come out
    unknown (rows, 6: a share under 0.5, or an unseen row). Read-only."""
    line = np.zeros((rows, 2))
    line[:seen] = 1.0
    share = np.empty_like(line)
    correlate1d(line, gaussian_weights(sigma), axis=0, output=share, mode="nearest")
    # (hand h's three columns are 3h..3h+2, as smooth's (rows, hands, 3) reshape lays them)
    divisor = np.repeat(np.maximum(share, 1e-12), 3, axis=1)
    unknown = np.repeat(share < 0.5, 3, axis=1)
    unknown[seen:] = True
    for a in (share, divisor, unknown):
        a.flags.writeable = False
    return share, divisor, unknown


def smooth_seen_prefix(x: np.ndarray, seen: int, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`smooth` of rows ``x`` (N, 6: both hands, contiguous) whose first ``seen`` rows
    are seen for both hands and the rest for neither (overwritten here: NaN where
    :func:`smooth` returns ``x`` itself, else zeros; not read): the same result, bit for bit,
    without finding that mask (the online cache knows it: its rows past the newest sample are
    the only unknown ones). The seen share returned may be read-only."""
    rows = x.shape[0]
    if seen >= rows and sigma > 0 and rows >= 2:
        return _smooth_all_seen(x, 2, sigma)
    if seen >= rows or sigma <= 0 or rows < 2:
        m = np.zeros((rows, 2), dtype=bool)
        m[:seen] = True
        x[seen:] = np.nan
        return smooth(x, m, sigma)
    # smooth's masked path with that mask: a seen row keeps its values and counts 1, an
    # unseen one counts 0 with zeros (np.where's), and unseen rows come out NaN. Each column
    # is correlated on its own (the same line, the same sums, whatever the array's shape), so
    # the positions take one correlation of x with zeros past the seen rows, and the mask's
    # correlation and what follows from it are the cached ones.
    share, divisor, unknown = _prefix_shares(rows, seen, sigma)
    x[seen:] = 0.0
    out = np.empty_like(x)
    correlate1d(x, gaussian_weights(sigma), axis=0, output=out, mode="nearest")
    np.divide(out, divisor, out=out)
    out[unknown] = np.nan  # do not invent samples inside long gaps, nor past the newest
    return out, share


# The largest (smallest) value of a float array that is not NaN, NaN if all are, ``initial``
# taking part if given: numpy's fmax (fmin) reduction, which is np.nanmax (np.nanmin) without
# its all-NaN warning (a window may hold no known value).
nanmax = np.fmax.reduce
nanmin = np.fmin.reduce


def vector_norm(v: np.ndarray) -> float:
    """The 2-norm of ``v``'s entries as a float."""
    return float(np.linalg.norm(v))


#: The share of the relative speed along the hands' line (the closing speed) under which
#: their relative motion runs mostly across it (the pair turning), and from which it runs
#: mostly toward or away from each other.
ALONG_LINE_SHARE = 0.5


def across_line(closing: np.ndarray, rel_speed: np.ndarray) -> np.ndarray:
    """Where the relative motion runs mostly across the hands' line (``closing`` and
    ``rel_speed`` in m/s, arrays or scalars; False where either is unknown)."""
    with np.errstate(invalid="ignore"):
        return np.abs(closing) < ALONG_LINE_SHARE * rel_speed


def _derived_into(
    x: np.ndarray,
    q: np.ndarray,
    norms: np.ndarray,
    closing: np.ndarray,
    common: np.ndarray,
    hold: np.ndarray,
) -> None:
    """From smoothed positions ``x`` (rows, both hands) and the velocities in ``q[2]`` (giver)
    and ``q[3]`` (receiver), row by row (a row's values depend on that row alone), written
    into: ``q`` (5, rows, 3) the relative position, relative velocity and the velocities' sum;
    ``norms`` (5, rows) the five vectors' norms (distance, relative speed, giver speed,
    receiver speed, and twice the common speed); ``closing``, ``common`` and ``hold`` (rows,)
    the closing, common and hold speeds (see :class:`Signals`). Each ``q[i]`` must be
    contiguous (as the einsum reads it)."""
    gv, rv = q[2], q[3]
    # The five vectors whose norms are needed, in one block.
    np.subtract(x[:, 3:], x[:, :3], out=q[0])
    np.subtract(rv, gv, out=q[1])
    np.add(gv, rv, out=q[4])
    norms[:] = np.linalg.norm(q, axis=2)
    np.multiply(0.5, norms[4], out=common)
    np.negative(np.einsum("ij,ij->i", q[1], q[0]), out=closing)
    np.divide(closing, np.maximum(norms[0], 1e-9), out=closing)
    np.maximum(np.abs(closing), norms[1] - np.minimum(norms[2], norms[3]), out=hold)


def _derived(
    x: np.ndarray, v: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
           np.ndarray, np.ndarray]:
    """From smoothed positions ``x`` and velocities ``v`` (rows, both hands): ``rel, rel_v,
    distance, rel_speed, giver_speed, receiver_speed, closing, common_speed, hold_speed``
    (:func:`_derived_into`, into new arrays)."""
    rows = x.shape[0]
    q, norms, speeds = np.empty((5, rows, 3)), np.empty((5, rows)), np.empty((3, rows))
    q[2] = v[:, :3]
    q[3] = v[:, 3:]
    _derived_into(x, q, norms, speeds[0], speeds[1], speeds[2])
    return q[0], q[1], norms[0], norms[1], norms[2], norms[3], speeds[0], speeds[1], speeds[2]


def _by_hand(rows: np.ndarray) -> np.ndarray:
    """Contiguous rows (N, 6) of both hands as a (2, N, 3) view: hand, row, coordinate."""
    return rows.reshape(rows.shape[0], 2, 3).transpose(1, 0, 2)


def _velocities(x: np.ndarray, full: np.ndarray, dt: float) -> np.ndarray:
    """Velocities of the smoothed rows ``x`` (at least two): central differences inside,
    one-sided at the ends, NaN where the smoothing window held less than ``FULL_WINDOW`` data
    (``full``, per row and hand)."""
    v = np.gradient(x, dt, axis=0)
    # Next to a tracking gap the window is one-sided and flattens the motion: velocities
    # there are unknown, not slow.
    v = v.reshape(v.shape[0], 2, 3)
    v[full < FULL_WINDOW] = np.nan
    return v.reshape(v.shape[0], 6)


def compute_signals(
    trajectory: Trajectory,
    config: PhaseConfig,
    cache: SignalCache | None = None,
    until: float = math.inf,
) -> Signals:
    """Frozen samples out, resample, smooth and differentiate the hands of ``trajectory``
    (sorted by time, see :meth:`Trajectory.cleaned`).

    ``cache``: an online caller's :class:`SignalCache`: when ``trajectory`` extends the one of
    the previous call (the same samples, more at the end), only the rows the new samples can
    change are computed; the result is the same, bit for bit. Its arrays are then read-only
    views, valid until the cache's next call. ``until``: only the grid rows at or before this
    time are returned (views of the whole result's first rows)."""
    if cache is not None:
        s = cache.extend(trajectory, config, until)
        if s is not None:
            return s
    t = trajectory.t
    n = t.shape[0]
    dt = 1.0 / config.analysis_rate
    grid = t.copy() if n < 2 else np.arange(t[0], t[-1] + 0.5 * dt, dt)
    p = np.concatenate((trajectory.giver_hand, trajectory.receiver_hand), axis=1)
    fin = np.isfinite(p)
    ok = fin[:, 0::3] & fin[:, 1::3] & fin[:, 2::3]  # (rows, hands): every coordinate seen
    seen = ok.copy() if cache is not None else ok  # (before stale samples are taken out)
    ok_g, ok_r = ok[:, 0], ok[:, 1]
    all_seen = bool(ok_g.all()) and bool(ok_r.all())
    # A stale repeat equals the sample before; with every sample seen and no coordinate equal
    # to the one before, there is none (the usual case: no per-hand search).
    if not (all_seen and not (p[1:] == p[:-1]).any()):
        ok_g &= ~drop_frozen(t, p[:, :3], config.frozen_speed, ok_g)
        ok_r &= ~drop_frozen(t, p[:, 3:], config.frozen_speed, ok_r)
        all_seen = False
    if _steps_beyond(p, config.glitch_jump) or not all_seen:
        bad_g = drop_glitches(t, p[:, :3], config.glitch_jump, ok_g)
        bad_r = drop_glitches(t, p[:, 3:], config.glitch_jump, ok_r)
        if bad_g.any() or bad_r.any():
            ok_g &= ~bad_g
            ok_r &= ~bad_r
            all_seen = False
    if all_seen:
        x = resample(t, p, None, grid, config.max_gap_hold)
    elif np.array_equal(ok_g, ok_r):  # both hands seen at the same samples
        x = resample(t, p, ok_g, grid, config.max_gap_hold)
    else:
        x = np.concatenate(
            (
                resample(t, p[:, :3], ok_g, grid, config.max_gap_hold),
                resample(t, p[:, 3:], ok_r, grid, config.max_gap_hold),
            ),
            axis=1,
        )
    # Smooth at least over a couple of input samples: 8 Hz data interpolated to 100 Hz has
    # corners at every sample that would otherwise show up as speed spikes.
    med_dt = float(np.median(np.diff(t))) if n > 1 else dt
    sigma_s = max(0.5 * config.smoothing, 0.5 * med_dt)
    fin = np.isfinite(x)
    m = fin[:, 0::3] & fin[:, 1::3] & fin[:, 2::3]  # (rows, hands)
    x, full = smooth(x, m, sigma_s / dt)
    v = _velocities(x, full, dt) if grid.shape[0] >= 2 else np.full_like(x, np.nan)
    rel, rel_v, distance, rel_speed, g_speed, r_speed, closing, common, hold = _derived(x, v)
    s = Signals(
        t=grid,
        giver=x[:, :3],
        receiver=x[:, 3:],
        giver_v=v[:, :3],
        receiver_v=v[:, 3:],
        rel=rel,
        rel_v=rel_v,
        distance=distance,
        rel_speed=rel_speed,
        giver_speed=g_speed,
        receiver_speed=r_speed,
        closing=closing,
        common_speed=common,
        hold_speed=hold,
    )
    if cache is not None:
        cache.keep(trajectory, config, s, x, full, sigma_s / dt, seen, ok)
    if until < math.inf:
        s = _first_rows(s, int(grid.searchsorted(until, side="right")))
    return s


def _first_rows(s: Signals, rows: int) -> Signals:
    """The first ``rows`` grid rows of ``s`` (views)."""
    return Signals(**{name: a[:rows] for name, a in vars(s).items()})


# The per-row blocks a SignalCache keeps beside the grid: name -> row shape (one row per grid
# row; the derived blocks are laid out as _derived_into writes them).
_BLOCKS = {"x": (6,), "full": (2,), "q": (5, 3), "norms": (5,), "speeds": (3,)}
# Where each Signals field derived from the rows sits: (block, index in the block's first axis),
# in the fields' order.
_IN_BLOCK = {
    "giver_v": ("q", 2), "receiver_v": ("q", 3), "rel": ("q", 0), "rel_v": ("q", 1),
    "distance": ("norms", 0), "rel_speed": ("norms", 1), "giver_speed": ("norms", 2),
    "receiver_speed": ("norms", 3), "closing": ("speeds", 0), "common_speed": ("speeds", 1),
    "hold_speed": ("speeds", 2),
}
# The blocks _derived_into writes, laid out (block axis, rows, ...).
_DERIVED_BLOCKS = ("q", "norms", "speeds")


class SignalCache:
    """The last signals :func:`compute_signals` computed for one online caller, so that the
    next call, on the same samples and a few more, computes only the rows the new samples can
    change: every grid row from half a smoothing kernel before the first grid point past the
    previous last valid sample of either hand (the interpolation there, the gaps' NaN and the
    smoothing's end padding change), and one more row for the central differences. Older
    rows keep their values, bit for bit: each step (interpolation between the valid samples
    around a grid point, a gap's length, a correlation over the kernel, row-wise arithmetic)
    reads only that neighbourhood, and which samples are stale repeats is decided in time
    order (a new sample never changes an older one's).

    A full computation starts the cache afresh when the window does not extend the last one
    (its first sample or an older sample changed), the smoothing width changed, or a hand has
    no valid sample before the rows to recompute.

    ``append_only``: the caller's windows are all cut from one stream of samples that only
    grows at its end (the online detector's): a window with the kept first sample's time and
    more samples then holds the kept samples unchanged, so they are not compared (nor kept).
    """

    def __init__(self, append_only: bool = False) -> None:
        self._append_only = append_only
        self._config: PhaseConfig | None = None  # None: nothing kept
        self._n = 0  # samples kept
        self._t_first = self._t_last = math.nan  # their first and last times
        self._t = np.empty(0)  # the samples the kept signals came from (unless append_only)
        self._g = np.empty((0, 3))
        self._r = np.empty((0, 3))
        # per sample and hand: every coordinate seen, and also not a stale repeat; None while
        # every sample kept is both (_clean: one interpolation for both hands)
        self._seen: np.ndarray | None = None
        self._ok: np.ndarray | None = None
        self._clean = False
        self._last_seen = [-1, -1]  # per hand: the last sample kept that was seen (-1: none)
        self._max_dt = 0.0
        self._sigma = 0.0
        self._grid = np.empty(0)
        self._rows = 0  # grid rows kept
        self._buf: dict[str, np.ndarray] = {}  # the blocks (owned, or a full result's arrays)
        self._owned = False  # the blocks are this cache's (else: a returned result's arrays)
        self._read_only: dict[str, np.ndarray] = {}  # read-only views: the results' fields

    def keep(
        self,
        trajectory: Trajectory,
        config: PhaseConfig,
        s: Signals,
        x: np.ndarray,
        full: np.ndarray,
        sigma: float,
        seen: np.ndarray,
        ok: np.ndarray,
    ) -> None:
        """Remember a full computation's result ``s`` with its smoothed rows ``x``, window
        shares ``full``, smoothing width ``sigma`` (grid steps) and, per sample
        and hand, which samples were ``seen`` and which were valid (``ok``: seen and not
        stale). The arrays are adopted, not copied: the first extension copies what it
        keeps."""
        t = trajectory.t
        if s.t.shape[0] < 3 or t.shape[0] < 2:
            self._config = None
            return
        self._config = config
        self._n = t.shape[0]
        self._t_first, self._t_last = float(t[0]), float(t[-1])
        if not self._append_only:
            self._t = t.copy()
            self._g = trajectory.giver_hand.copy()
            self._r = trajectory.receiver_hand.copy()
        self._clean = bool(ok.all())
        self._seen, self._ok = (None, None) if self._clean else (seen, ok)
        self._last_seen = [self._last_of(seen[:, h]) for h in (0, 1)]
        self._max_dt = float((t[1:] - t[:-1]).max())
        self._sigma = sigma
        self._grid = s.t
        self._rows = s.t.shape[0]
        self._buf = {"x": x, "full": full}
        self._buf.update({name: getattr(s, name) for name in _IN_BLOCK})
        self._owned = False

    @staticmethod
    def _last_of(mask: np.ndarray) -> int:
        """Index of the last True of ``mask`` (-1: none), searched from the end."""
        i = mask.shape[0] - 1
        while i >= 0 and not mask[i]:
            i -= 1
        return i

    def _masks(self) -> tuple[np.ndarray, np.ndarray]:
        """Per sample kept and hand: seen, and valid (all True while the cache is clean)."""
        if self._seen is None or self._ok is None:
            every = np.ones((self._n, 2), dtype=bool)
            return every, every
        return self._seen, self._ok

    def _same_prefix(self, t: np.ndarray, g: np.ndarray, r: np.ndarray) -> bool:
        """The first samples of ``t``, ``g``, ``r`` are the ones kept, bit for bit (NaN too)."""
        n0 = self._n
        if t[0] != self._t_first or t[n0 - 1] != self._t_last:
            return False
        if self._append_only:
            return True  # (the same first sample of one growing stream: the same samples)
        if not (t[:n0] == self._t).all():
            return False
        if self._clean:  # (no NaN kept: value equality is enough)
            return bool((g[:n0] == self._g).all() and (r[:n0] == self._r).all())
        bits = np.int64
        gk, rk = np.ascontiguousarray(g[:n0]), np.ascontiguousarray(r[:n0])
        return bool(
            (gk.view(bits) == self._g.view(bits)).all()
            and (rk.view(bits) == self._r.view(bits)).all()
        )

    def _new_valid(
        self, t: np.ndarray, p: np.ndarray, hand: int, config: PhaseConfig
    ) -> tuple[np.ndarray, np.ndarray]:
        """Which of the new samples of one hand (``p``: all its samples) are seen, and which
        of those are neither stale repeats (:func:`drop_frozen`) nor glitches
        (:func:`drop_glitches`), whose decisions run in time order: run on the whole window
        only when a new seen sample repeats the one before or steps more than
        ``glitch_jump`` from it."""
        n0 = self._n
        fin = np.isfinite(p[n0:])
        seen_new = fin[:, 0] & fin[:, 1] & fin[:, 2]
        rows = seen_new.nonzero()[0] + n0
        before = self._last_seen[hand]
        if before >= 0:
            rows = np.concatenate(([before], rows))
        q = p[rows]
        if rows.size < 2:
            return seen_new, seen_new
        repeats = bool((q[1:] == q[:-1]).all(axis=1).any())
        jump = config.glitch_jump
        steps = jump > 0 and bool((np.linalg.norm(q[1:] - q[:-1], axis=1) > jump).any())
        if not (repeats or steps):
            return seen_new, seen_new
        seen_all = np.concatenate((self._masks()[0][:, hand], seen_new))
        ok_all = seen_all & ~drop_frozen(t, p, config.frozen_speed, seen_all)
        ok_all &= ~drop_glitches(t, p, jump, ok_all)
        return seen_new, ok_all[n0:]

    def extend(
        self, trajectory: Trajectory, config: PhaseConfig, until: float = math.inf
    ) -> Signals | None:
        """The signals of ``trajectory`` if it extends the samples kept (see the class
        docstring), else ``None`` (the caller computes them in full); ``until``: see
        :func:`compute_signals`."""
        if self._config is None or (config is not self._config and config != self._config):
            return None
        t = trajectory.t
        g_in, r_in = trajectory.giver_hand, trajectory.receiver_hand
        n, n0 = t.shape[0], self._n
        if n <= n0 or not self._same_prefix(t, g_in, r_in):
            return None
        # The new samples: seen and valid per hand. The usual case, every one seen and none
        # repeating a coordinate of the one before, needs no per-hand search.
        tail = np.concatenate((g_in[n0 - 1 :], r_in[n0 - 1 :]), axis=1)
        clean = (
            self._clean
            and bool(np.isfinite(tail).all())
            and not (tail[1:] == tail[:-1]).any()
            and not _steps_beyond(tail, config.glitch_jump)
        )
        if not clean:
            sg, og = self._new_valid(t, g_in, 0, config)
            sr, orr = self._new_valid(t, r_in, 1, config)
            seen_new, ok_new = np.stack((sg, sr), axis=1), np.stack((og, orr), axis=1)
        max_dt = max(self._max_dt, float(np.diff(t[n0 - 1 :]).max()))
        dt = 1.0 / config.analysis_rate
        # The smoothing width: half the median sample interval only counts when it exceeds
        # half the smoothing, which needs an interval that long.
        sigma_s = 0.5 * config.smoothing
        if max_dt > config.smoothing:
            sigma_s = max(sigma_s, 0.5 * float(np.median(np.diff(t))))
        if sigma_s / dt != self._sigma:
            return None
        grid = np.arange(t[0], t[-1] + 0.5 * dt, dt)
        rows, rows0 = grid.shape[0], self._rows
        w = gaussian_weights(self._sigma)
        radius = w.shape[0] // 2
        # the first grid row past the last valid sample kept of either hand: NaN before, or
        # beyond the kept grid
        if self._clean:
            last_valid = self._t_last
        else:
            ok_old = self._masks()[1]
            k_g, k_r = ok_old[:, 0].nonzero()[0], ok_old[:, 1].nonzero()[0]
            if k_g.size < 2 or k_r.size < 2:
                return None  # (a hand with fewer was all unknown: its first rows change too)
            last_valid = float(t[min(int(k_g[-1]), int(k_r[-1]))])
        j_c = int(self._grid.searchsorted(last_valid, side="right"))
        a = j_c - radius  # first smoothed row that changes
        # (scipy's correlation of a line that starts at row i0 equals the whole line's only
        # from row i0 + radius + 1 on: the slice starts one row earlier than the kernel needs)
        lead = radius + 1
        if a - lead < 0 or a < 2 or rows < rows0 or grid[rows0 - 1] != self._grid[-1]:
            return None
        # interpolate the rows the smoothing of rows a.. reads (from the sample before them)
        gs = grid[a - lead :]
        xr = np.empty((gs.shape[0], 6))
        bar = config.max_gap_hold + 1e-9
        seen_rows = -1  # (>= 0: the rows before it are seen for both hands, none after)
        if clean:
            i_s = max(int(t.searchsorted(gs[0], side="right")) - 1, 0)
            ts = t[i_s:]
            for k in range(3):
                xr[:, k] = np.interp(gs, ts, g_in[i_s:, k])
                xr[:, 3 + k] = np.interp(gs, ts, r_in[i_s:, k])
            # (no step of the window is longer than bar: none of ts's is)
            if max_dt > bar and ts.shape[0] > 1 and float((ts[1:] - ts[:-1]).max()) > bar:
                xr[_far_from_samples(ts, gs, bar)] = np.nan  # (resample's long-gap path)
            else:
                # (only the rows past the newest sample are unknown: smoothed as such)
                seen_rows = int(gs.searchsorted(t[-1], side="right"))
        else:
            i_t = int(t.searchsorted(gs[0], side="right")) - 1  # the sample at or before
            ok_old = self._masks()[1]
            for hand, p_in in enumerate((g_in, r_in)):
                ok_hand = ok_old[:, hand]
                i_s = min(i_t, n0 - 1)
                while i_s >= 0 and not ok_hand[i_s]:  # the valid sample at or before the rows
                    i_s -= 1
                if i_s < 0:
                    return None  # (none: the rows were unknown and may not stay so)
                valid = np.concatenate((ok_hand[i_s:], ok_new[:, hand]))
                tv, pv = t[i_s:][valid], p_in[i_s:][valid]
                cols = slice(3 * hand, 3 * hand + 3)
                for k in range(3):
                    xr[:, 3 * hand + k] = np.interp(gs, tv, pv[:, k])
                # (what resample's two ways of marking far grid points both give here)
                xr[_far_from_samples(tv, gs, bar), cols] = np.nan
        self._reserve(rows, a)
        b = self._buf
        if seen_rows >= 0:
            xs, full = smooth_seen_prefix(xr, seen_rows, self._sigma)
        else:
            fin = np.isfinite(xr)
            m = fin[:, 0::3] & fin[:, 1::3] & fin[:, 2::3]
            xs, full = smooth(xr, m, self._sigma)
        b["x"][a:rows] = xs[lead:]
        b["full"][a:rows] = full[lead:]
        # velocities from row a - 1 (its central difference reads row a), as _velocities
        # gives them, written where _derived_into reads them (giver, receiver)
        x, q = b["x"], b["q"][:, a - 1 : rows]
        vq = q[2:4]
        vq[:] = _by_hand(_velocities(x[a - 2 : rows], b["full"][a - 2 : rows], dt)[1:])
        sp = b["speeds"][:, a - 1 : rows]
        _derived_into(x[a - 1 : rows], q, b["norms"][:, a - 1 : rows], sp[0], sp[1], sp[2])
        if not self._append_only:
            self._t, self._g, self._r = t.copy(), g_in.copy(), r_in.copy()
        if clean:
            self._last_seen = [n - 1, n - 1]
        else:
            seen_old, ok_old = self._masks()
            self._seen = np.concatenate((seen_old, seen_new))
            self._ok = np.concatenate((ok_old, ok_new))
            self._last_seen = [self._last_of(self._seen[:, h]) for h in (0, 1)]
        self._n, self._t_last = n, float(t[-1])
        self._clean = clean
        self._max_dt = max_dt
        self._grid, self._rows = grid, rows
        keep = rows if until == math.inf else int(grid.searchsorted(until, side="right"))
        ro = self._read_only
        xv = ro["x"][:keep]
        fields = {"t": grid[:keep], "giver": xv[:, :3], "receiver": xv[:, 3:]}
        for name in _IN_BLOCK:  # (in the fields' order)
            fields[name] = ro[name][:keep]
        return Signals(**fields)

    def _reserve(self, rows: int, keep: int) -> None:
        """Blocks of at least ``rows`` rows, owned by the cache, holding the first ``keep``
        rows kept."""
        if self._owned and self._buf["x"].shape[0] >= rows:
            return
        cap = max(2 * rows, 256)
        old = {**self._buf, **self._read_only} if self._owned else self._buf
        new: dict[str, np.ndarray] = {}
        for name, shape in _BLOCKS.items():
            # (the row axis after the block axis, so each field's rows are contiguous)
            new[name] = np.empty((shape[0], cap, *shape[1:]) if name in _DERIVED_BLOCKS
                                 else (cap, *shape))
        ro: dict[str, np.ndarray] = {}
        for name in ("x", "full"):
            new[name][:keep] = old[name][:keep]
            ro[name] = new[name].view()
        for name, (block, i) in _IN_BLOCK.items():
            field = new[block][i]
            field[:keep] = old[name][:keep]
            ro[name] = field.view()
        for view in ro.values():
            view.flags.writeable = False  # (the results' views: read-only)
        self._buf, self._read_only, self._owned = new, ro, True

