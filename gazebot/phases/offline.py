"""Offline segmentation of a whole recording into reach, transfer and retreat.

With the whole recording at hand the seed's rule (section 7.2.5) applies as written: transfer is
where the hands are within ``transfer_distance_margin`` (20 cm) of their minimum distance and their
relative speed is below ``transfer_speed_max`` (15 cm/s). Steps:

1. Resample onto a uniform grid (``offline_rate``), bridging gaps up to ``max_gap_hold``;
   zero-lag Gaussian smoothing (``smoothing``); velocities by central differences.
2. Every dip of the hands' distance at least ``min_approach`` deep is a handover candidate; its
   minimum is the seed's "minimum distance" (so a recording may hold several handovers).
3. Within a dip, the seed rule's run around the minimum is the transfer core; runs separated by
   blips shorter than ``min_transfer`` while the speed stays below ``transfer_exit_speed``, or by
   tracking gaps, are merged (hysteresis). No handover: a core shorter than ``min_transfer``, a
   minimum farther than ``contact_distance_max``, or a dip the giver's hand did not reach into
   (e.g. a robot gripper returning home near a resting giver).
4. Boundaries are refined with the minimum-jerk profile: the seed's 15 cm/s is crossed on the
   tail of the approach, before contact, so the transfer starts where the relative speed
   settles below ``settle_speed`` (or stops falling below ``settle_floor_speed``: tracking noise
   can hold it above ``settle_speed``), pushed on by the parabolic-tail extrapolation of the two
   crossings (``stop_extrapolation``). Only the tail seen before a tracking gap counts; an
   approach that stops inside a gap is dated from the last sample before it. The release is
   back-dated from where the hands' relative position has left the held pose by
   ``release_distance`` with ``t0 = t - 3 x / v``, as the hands leave rest along a minimum-jerk
   start (``x ~ (t - t0)^3``). If the release falls in a tracking gap, the separation seen
   before the gap dates it, else the giver's own motion onset after it. A refinement that would
   shrink a transfer below ``min_transfer`` is dropped for the rule's own run.
5. The reach starts at the giver's motion onset before the transfer (speed above
   ``reach_onset_speed`` after the last slow sample *seen*, back-dated the same way from the
   last rest sample seen: an onset hidden in a tracking gap is dated across the gap, not at its
   end); the retreat ends at the earliest of the giver's hand back at rest (the mirror image,
   with hysteresis down to ``rest_speed``), the hand ``retreat_far_distance`` from where the
   transfer happened (as online), the next reach, and the data end.
6. A recording that ends mid-handover ends in the phase under way, at its last sample, with
   nothing invented after it: if the hands never part by ``release_distance`` before the data
   end (or the tracking is lost for good with nothing moving), the transfer runs to the end and
   there is no retreat; if the hands are still closing and no transfer was found, a lone reach
   runs to the end.

The robot's gripper/load-share columns are not used offline: at low sampling rates their first
sample after the release is later than the back-dated kinematic estimate (the online detector
uses them, where they arrive before the motion shows).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gazebot.phases.config import PhaseConfig
from gazebot.phases.segment import Segment
from gazebot.phases.trajectory import Trajectory
from gazebot.types import Phase


@dataclass(frozen=True)
class Signals:
    """The smoothed signals the segmentation works on (uniform grid, NaN where unknown).

    Attributes:
        t: Grid times (N,) s.
        giver: Giver hand positions (N, 3) m.
        receiver: Receiver hand positions (N, 3) m.
        giver_v: Giver hand velocities (N, 3) m/s.
        rel: Relative position receiver - giver (N, 3) m.
        rel_v: Relative velocity (N, 3) m/s.
        distance: Hands' distance (N,) m.
        rel_speed: Relative speed (N,) m/s.
        giver_speed: Giver hand speed (N,) m/s.
    """

    t: np.ndarray
    giver: np.ndarray
    receiver: np.ndarray
    giver_v: np.ndarray
    rel: np.ndarray
    rel_v: np.ndarray
    distance: np.ndarray
    rel_speed: np.ndarray
    giver_speed: np.ndarray


def _resample(t: np.ndarray, p: np.ndarray, grid: np.ndarray, max_gap: float) -> np.ndarray:
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
    exact = np.isin(grid, tv)
    out[(gap > max_gap + 1e-9) & ~exact] = np.nan
    return out


def _gauss(x: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian smoothing of the columns of ``x`` (edges padded with the end values)."""
    radius = max(1, int(math.ceil(3.0 * sigma)))
    k = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
    k /= k.sum()
    pad = np.pad(x, ((radius, radius),) + ((0, 0),) * (x.ndim - 1), mode="edge")
    if x.ndim == 1:
        return np.convolve(pad, k, mode="valid")
    return np.stack([np.convolve(pad[:, j], k, mode="valid") for j in range(x.shape[1])], axis=1)


def _smooth(x: np.ndarray, sigma: float) -> np.ndarray:
    """NaN-aware Gaussian smoothing along axis 0 (normalised convolution), zero lag."""
    m = np.isfinite(x).all(axis=1)
    if sigma <= 0 or x.shape[0] < 2:
        return x
    num = _gauss(np.where(m[:, None], x, 0.0), sigma)
    den = _gauss(m.astype(float), sigma)
    out = num / np.maximum(den, 1e-12)[:, None]
    out[(den < 0.5) | ~m] = np.nan  # do not invent samples inside long gaps
    return out


def compute_signals(trajectory: Trajectory, config: PhaseConfig) -> Signals:
    """Resample, smooth and differentiate the hands of ``trajectory`` (sorted by time)."""
    t = trajectory.t
    dt = 1.0 / config.offline_rate
    if t.shape[0] < 2:
        grid = t.copy()
    else:
        grid = np.arange(t[0], t[-1] + 0.5 * dt, dt)
    g = _resample(t, trajectory.giver_hand, grid, config.max_gap_hold)
    r = _resample(t, trajectory.receiver_hand, grid, config.max_gap_hold)
    # Smooth at least over a couple of input samples: 8 Hz data interpolated to 100 Hz has
    # corners at every sample that would otherwise show up as speed spikes.
    med_dt = float(np.median(np.diff(t))) if t.shape[0] > 1 else dt
    sigma_s = max(0.5 * config.smoothing, 0.5 * med_dt)
    g = _smooth(g, sigma_s / dt)
    r = _smooth(r, sigma_s / dt)
    if grid.shape[0] >= 2:
        gv = np.gradient(g, dt, axis=0)
        rv = np.gradient(r, dt, axis=0)
    else:
        gv = np.full_like(g, np.nan)
        rv = np.full_like(r, np.nan)
    rel = r - g
    rel_v = rv - gv
    return Signals(
        t=grid,
        giver=g,
        receiver=r,
        giver_v=gv,
        rel=rel,
        rel_v=rel_v,
        distance=np.linalg.norm(rel, axis=1),
        rel_speed=np.linalg.norm(rel_v, axis=1),
        giver_speed=np.linalg.norm(gv, axis=1),
    )


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive index ranges of the True runs of ``mask``."""
    if mask.size == 0:
        return []
    padded = np.concatenate([[False], mask, [False]])
    edges = np.flatnonzero(padded[1:] != padded[:-1])
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def _dips(d: np.ndarray, depth: float) -> list[tuple[int, int, int]]:
    """Dips of ``d`` at least ``depth`` deep on both sides, as ``(left, minimum, right)`` index
    triples (left/right: the highest points between neighbouring dips). The recording's ends
    count as high ground, so a recording that starts or ends mid-handover keeps its dip.
    NaN samples are skipped."""
    out: list[tuple[int, int, int]] = []
    idx = np.flatnonzero(np.isfinite(d))
    if idx.size == 0:
        return out
    vals = d[idx].tolist()
    left = int(idx[0])
    going_down = True
    lo_v, lo_i = math.inf, -1
    hi_v, hi_i = -math.inf, -1
    for i, v in zip(idx.tolist(), vals, strict=True):
        if going_down:
            if v < lo_v:
                lo_v, lo_i = v, i
            elif v >= lo_v + depth:
                going_down = False
                hi_v, hi_i = v, i
        else:
            if v > hi_v:
                hi_v, hi_i = v, i
            elif v <= hi_v - depth:
                out.append((left, lo_i, hi_i))
                left = hi_i
                going_down = True
                lo_v, lo_i = v, i
    if going_down:
        if lo_i >= 0:
            out.append((left, lo_i, int(idx[-1])))
    else:
        out.append((left, lo_i, hi_i if hi_i >= 0 else int(idx[-1])))
    return out


@dataclass(frozen=True)
class _Transfer:
    start: int
    end: int
    t_start: float
    t_end: float
    open_end: bool = False  # the data end before the release: the transfer runs to the end


def _find_transfers(s: Signals, c: PhaseConfig) -> list[_Transfer]:
    d = s.distance
    n = d.shape[0]
    if n < 3 or not np.isfinite(d).any():
        return []
    dt = 1.0 / c.offline_rate
    out: list[_Transfer] = []
    rs = np.where(np.isfinite(s.rel_speed), s.rel_speed, np.inf)
    min_len = max(1, int(round(c.min_transfer / dt)))
    for lo, p, hi in _dips(d, c.min_approach):
        if not np.isfinite(d[p]):
            continue
        dmin = d[p]
        near = np.zeros(n, dtype=bool)
        near[lo : hi + 1] = d[lo : hi + 1] <= dmin + c.transfer_distance_margin
        rule = near & (rs < c.transfer_speed_max)
        soft = near & (rs < c.transfer_exit_speed)
        runs = _runs(rule)
        if not runs:
            continue
        # Hysteresis: merge rule runs split by short blips that stay under the exit speed.
        merged: list[list[int]] = [list(runs[0])]
        unknown = ~np.isfinite(s.rel_speed)
        for a, b in runs[1:]:
            gap = slice(merged[-1][1] + 1, a)
            # Merge across a short blip under the exit speed, or across a tracking gap with
            # nothing but such samples (a dropout inside a transfer does not end it).
            ok = soft[gap] | unknown[gap]
            if ok.all() and np.count_nonzero(~unknown[gap]) < min_len:
                merged[-1][1] = b
            else:
                merged.append([a, b])
        # The run holding the minimum, else the longest one.
        core = next((m for m in merged if m[0] <= p <= m[1]), None)
        if core is None:
            core = max(merged, key=lambda m: m[1] - m[0])
        a, b = core
        if b - a + 1 < min_len or dmin > c.contact_distance_max:
            continue
        # The giver must have reached: a receiver (robot) returning home to a resting giver
        # also makes a dip.
        if not np.nanmax(s.giver_speed[lo : a + 1], initial=0.0) >= c.reach_onset_speed:
            continue
        if out and a <= out[-1].end:
            continue  # same transfer seen from a neighbouring dip
        t_start = _refine_start(s, c, a, b)
        t_end, open_end = _refine_end(s, c, a, b, t_start)
        if open_end:
            out.append(_Transfer(a, b, t_start, float(s.t[-1]), True))
            break  # the hands never part again in this recording
        if t_end - t_start < c.min_transfer:
            # The refinement assumes clean minimum-jerk edges; when it collapses a short
            # transfer (fast giver, sparse samples) the seed rule's own run stands.
            t_start, t_end = float(s.t[a]), float(s.t[b])
        out.append(_Transfer(a, b, t_start, t_end))
    return out


def _refine_start(s: Signals, c: PhaseConfig, a: int, b: int) -> float:
    """Where the approach stops: the relative speed settles after the seed-rule crossing.

    Only the tail seen before the first tracking gap counts: a settle time found after a gap is
    late by up to the gap's length, and the extrapolation below would scale that error up. When
    the speed does not settle in the seen tail (a gap, or noise above ``settle_speed``), the
    stop is extrapolated from the slowest seen sample instead.
    """
    hidden = _stop_in_gap_before(s, c, a)
    if hidden is not None:
        return hidden
    dt = 1.0 / c.offline_rate
    stop = min(b, a + int(c.max_refine / dt))
    seg = s.rel_speed[a : stop + 1]
    gaps = np.flatnonzero(~np.isfinite(seg))
    seen = seg[: int(gaps[0])] if gaps.size else seg
    t_a = float(s.t[a])
    # The tail ends where the speed settles below ``settle_speed``, or where it stops falling
    # below ``settle_floor_speed`` (tracking noise above ``settle_speed`` would otherwise date
    # a random later dip, and the extrapolation would scale that delay up).
    below = seen < c.settle_speed
    if seen.size >= 2:
        floor = max(c.settle_floor_speed, c.settle_speed)
        below[:-1] |= (seen[1:] >= seen[:-1]) & (seen[:-1] < floor)
    if not below.any():
        below[-1] = True
    i_s = a + int(np.argmax(below))
    v_s = max(float(seen[i_s - a]), c.settle_speed)
    # On the minimum-jerk tail the speed falls as (t_stop - t)^2: the times it crosses the
    # seed's threshold and a lower speed extrapolate to the stop (scaled down: smoothing and
    # the (1 - t/T)^2 factor make the real tail flatter than a parabola).
    ratio = math.sqrt(c.transfer_speed_max / max(v_s, 1e-9)) - 1.0
    if ratio <= 0.05:
        return t_a  # the speed did not fall: nothing to extrapolate
    t_s = float(s.t[i_s])
    return t_s + min(c.stop_extrapolation * (t_s - t_a) / ratio, c.max_refine)


def _stop_in_gap_before(s: Signals, c: PhaseConfig, a: int) -> float | None:
    """The approach's stop when it hides in a tracking gap ending at grid index ``a``.

    ``None`` if ``a`` follows a seen sample, or the hands have not settled at ``a`` (still
    approaching after the gap). Else, from the last sample seen before the gap, approaching at
    speed ``v`` with ``x`` left to go, the minimum-jerk tail (``x ~ (t_stop - t)^3``) stops
    ``3 x / v`` later; at the latest when the gap ends."""
    if a == 0 or np.isfinite(s.rel_speed[a - 1]) or not s.rel_speed[a] < c.settle_speed:
        return None  # seen crossing, or still approaching after the gap
    seen = np.flatnonzero(np.isfinite(s.rel_speed[:a]))
    t_a = float(s.t[a])
    if seen.size == 0:
        return None
    i = int(seen[-1])
    x = float(np.linalg.norm(s.rel[a] - s.rel[i]))
    v = float(s.rel_speed[i])
    if not (math.isfinite(x) and v > 1e-6):
        return t_a
    return min(float(s.t[i]) + 3.0 * x / v, t_a)


def _refine_end(s: Signals, c: PhaseConfig, a: int, b: int, t_start: float) -> tuple[float, bool]:
    """Back-date the release from the rule's exit with the minimum-jerk start ``3 x / v``.

    Returns ``(t_end, open_end)``. ``open_end`` is True when the data end before the release is
    seen (the separation never reaches ``release_distance``, or the tracking is lost for good
    with no motion of the giver after it): the transfer then runs to the end of the data
    instead of being back-dated from a separation that never happened.
    """
    settled = (s.t[a : b + 1] >= t_start) & (s.rel_speed[a : b + 1] < c.settle_speed)
    idx = np.flatnonzero(settled) + a
    if idx.size == 0:
        idx = np.arange(a, b + 1)
    held = np.nanmedian(s.rel[idx], axis=0)
    # Follow the exit until the separation is unmistakable, then extrapolate back.
    n = s.t.shape[0]
    j = b
    while j + 1 < n and np.linalg.norm(s.rel[j] - held) < c.release_distance:
        if not np.isfinite(s.rel_speed[j + 1]):
            # The release is hidden in a tracking gap. When the hands were already parting
            # before it, back-date from the last sample seen (a motion onset found after the
            # gap is late by up to the gap's length); else fall back on the giver's own
            # motion onset, when the giver's hand is seen.
            sep = float(np.linalg.norm(s.rel[j] - held))
            v = float(s.rel_speed[j])
            if sep >= 0.5 * c.release_distance and v > 1e-6:
                return max(float(s.t[j]) - min(3.0 * sep / v, c.max_refine), t_start), False
            onset = _giver_onset_after(s, c, j)
            if onset is None and not np.isfinite(s.rel_speed[j + 1 :]).any():
                return float(s.t[-1]), True  # tracking lost until the end, nothing moved
            return max(float(s.t[j]) if onset is None else onset, t_start), False
        j += 1
    if j == n - 1 and not np.linalg.norm(s.rel[j] - held) >= c.release_distance:
        return float(s.t[-1]), True
    sep = float(np.linalg.norm(s.rel[j] - held))
    v = float(s.rel_speed[j])
    back = 3.0 * sep / v if v > 1e-6 and math.isfinite(sep) else 0.0
    t_end = float(s.t[j]) - min(back, c.max_refine)
    return max(t_end, t_start), False


def _giver_onset_after(s: Signals, c: PhaseConfig, j: int) -> float | None:
    """Start of the giver's first motion after grid index ``j`` (``None`` if none is seen)."""
    v = s.giver_speed[j:]
    fast = np.flatnonzero(v >= c.reach_onset_speed)
    if fast.size == 0:
        return None
    i = j + int(fast[0])
    x = float(np.linalg.norm(s.giver[i] - s.giver[j]))
    back = 3.0 * x / float(v[fast[0]]) if math.isfinite(x) else 0.0
    # Across a tracking gap the motion may have started anywhere in it: the cap grows by the
    # time not seen (never before the last sample seen, ``j``).
    unseen = float(np.count_nonzero(~np.isfinite(v[: fast[0]]))) / c.offline_rate
    return max(float(s.t[i]) - min(back, c.max_refine + unseen), float(s.t[j]))


def _onset_before(s: Signals, c: PhaseConfig, lo: int, hi: int) -> float:
    """Start of the giver's reach before grid index ``hi`` (not before index ``lo``): the
    fastest motion in the window (small adjustments near the receiver may follow it)."""
    v = s.giver_speed[lo : hi + 1]
    if hi <= lo or not np.nanmax(v, initial=0.0) >= c.reach_onset_speed:
        return float(s.t[lo])
    peak = int(np.nanargmax(v))
    # The crossing follows the last sample *seen* slow: a tracking gap inside the reach is
    # not its onset (the fastest part may come after such a gap).
    head = v[: peak + 1]
    seen = np.isfinite(head)
    slow = np.flatnonzero(seen & (head < c.reach_onset_speed))
    if slow.size:
        i_c = lo + int(slow[-1]) + 1 + int(np.argmax(seen[slow[-1] + 1 :]))
    else:
        slow = np.flatnonzero(~seen)  # only a gap before the motion: it may hide the onset
        if slow.size == 0:
            return float(s.t[lo])  # already moving when the data start
        i_c = lo + int(slow[-1]) + 1
    # The last *seen* rest: when the onset hides in a tracking gap, the displacement across
    # the gap still dates it (not before that rest sample).
    rest = np.flatnonzero(s.giver_speed[lo:i_c] < c.rest_speed)
    i_r = lo + int(rest[-1]) if rest.size else lo
    x = float(np.linalg.norm(s.giver[i_c] - s.giver[i_r]))
    speed = float(s.giver_speed[i_c])
    back = 3.0 * x / speed if math.isfinite(x) and speed > 0 else 0.0
    floor = float(s.t[lo])
    if i_c - i_r > 1 and not np.isfinite(s.giver_speed[i_r + 1 : i_c]).all():
        floor = max(floor, float(s.t[i_r]))
    return max(float(s.t[i_c]) - min(back, c.max_refine), floor)


def _rest_after(s: Signals, c: PhaseConfig, lo: int, hi: int) -> float:
    """End of the giver's first motion after grid index ``lo`` (not after index ``hi``)."""
    hi = min(hi, lo + int(c.max_retreat * c.offline_rate), s.t.shape[0] - 1)
    v = s.giver_speed[lo : hi + 1]
    fast = np.flatnonzero(v >= c.reach_onset_speed)
    if hi <= lo or fast.size == 0:
        return float(s.t[hi])
    # The motion lasts until the hand is at rest (hysteresis: a slow hand's speed may dip
    # below ``reach_onset_speed`` on the way); it decelerates through that speed at its last
    # fast sample.
    tail = v[fast[0] :]
    rest = np.flatnonzero(tail < c.rest_speed)
    if rest.size == 0 and not (tail[-1] < c.reach_onset_speed):
        return float(s.t[hi])  # still moving when the data (or the window) end
    i_r = lo + int(fast[0]) + (int(rest[0]) if rest.size else tail.size - 1)
    moving = np.flatnonzero(s.giver_speed[lo + int(fast[0]) : i_r + 1] >= c.reach_onset_speed)
    i_c = lo + int(fast[0]) + int(moving[-1])
    x = float(np.linalg.norm(s.giver[i_r] - s.giver[i_c]))
    speed = float(s.giver_speed[i_c])
    fwd = 3.0 * x / speed if math.isfinite(x) and speed > 0 else 0.0
    return min(float(s.t[i_c]) + min(fwd, c.max_refine), float(s.t[hi]))


def _far_after(s: Signals, c: PhaseConfig, i_end: int) -> float:
    """First time after grid index ``i_end`` (the release) that the giver's hand is
    ``retreat_far_distance`` from where the transfer happened (``inf`` if never)."""
    seen = np.flatnonzero(np.isfinite(s.giver[: i_end + 1]).all(axis=1))
    if seen.size == 0:
        return math.inf
    moved = np.linalg.norm(s.giver[i_end:] - s.giver[int(seen[-1])], axis=1)
    far = np.flatnonzero(moved >= c.retreat_far_distance)  # NaN: not seen far
    return float(s.t[i_end + int(far[0])]) if far.size else math.inf


def _trailing_reach(s: Signals, c: PhaseConfig, lo: int) -> float | None:
    """Onset of a reach still under way when the data end (after grid index ``lo``), or
    ``None``: the giver's hand moved (``reach_onset_speed``), the hands closed by at least
    ``min_approach`` from their farthest since ``lo``, and they are at their closest at the end
    (no transfer was found, so the reach has not ended)."""
    d = s.distance[lo:]
    seen = np.flatnonzero(np.isfinite(d))
    if seen.size < 3:
        return None
    i_max = int(np.nanargmax(d))
    last = float(d[seen[-1]])
    tail_min = float(np.nanmin(d[i_max:]))
    if d[i_max] - last < c.min_approach or last > tail_min + 0.5 * c.min_approach:
        return None
    if not np.nanmax(s.giver_speed[lo + i_max :], initial=0.0) >= c.reach_onset_speed:
        return None  # only the receiver came closer
    return _onset_before(s, c, lo, lo + int(seen[-1]))


def segment(trajectory: Trajectory, config: PhaseConfig | None = None) -> list[Segment]:
    """Split a recording into contiguous reach, transfer and retreat segments per handover.

    The trajectory is sorted by time first (duplicates dropped, see :meth:`Trajectory.cleaned`).
    Returns segments in time order; within a handover they are contiguous (reach end = transfer
    start, transfer end = retreat start), and handovers never overlap. The retreat ends at the
    earlier of the giver's hand coming to rest and its being ``retreat_far_distance`` from
    where the transfer happened (or when the next reach starts).

    A recording cut short ends in the phase under way, which ends at the last sample, and
    invents nothing after it: cut mid-retreat, the retreat runs to the end; cut mid-transfer
    (the hands never part by ``release_distance``), the transfer runs to the end and has no
    retreat; cut mid-reach (the hands still closing, no transfer), a lone reach runs to the end.
    A recording with neither a transfer nor a reach under way at its end yields no segments.
    """
    c = config if config is not None else PhaseConfig()
    traj, _, _ = trajectory.cleaned()
    if len(traj) < 3:
        return []
    s = compute_signals(traj, c)
    t_last = float(traj.t[-1])
    grid_end = float(s.t[-1])

    def at_end(x: float) -> float:
        # The grid's last point is within half a step of the last sample: name it exactly.
        return t_last if x >= grid_end - 1e-9 else x

    transfers = _find_transfers(s, c)
    out: list[Segment] = []
    t_idx = s.t
    prev_end_idx = 0
    for k, tr in enumerate(transfers):
        t_start = min(tr.t_start, t_last)  # an extrapolated stop never passes the data end
        i_start = int(np.searchsorted(t_idx, t_start))
        reach_start = _onset_before(s, c, prev_end_idx, max(i_start - 1, prev_end_idx))
        if out:
            reach_start = max(reach_start, out[-1].end)
        out.append(Segment(Phase.REACH, min(reach_start, t_start), t_start, k))
        if tr.open_end:
            out.append(Segment(Phase.TRANSFER, t_start, t_last, k))
            break
        i_end = min(int(np.searchsorted(t_idx, tr.t_end)), len(t_idx) - 1)
        nxt = transfers[k + 1].start if k + 1 < len(transfers) else len(t_idx) - 1
        retreat_end = min(_rest_after(s, c, i_end, max(nxt, i_end)), _far_after(s, c, i_end))
        retreat_end = at_end(max(retreat_end, tr.t_end))
        out.append(Segment(Phase.TRANSFER, tr.t_start, tr.t_end, k))
        out.append(Segment(Phase.RETREAT, tr.t_end, retreat_end, k))
        prev_end_idx = int(np.searchsorted(t_idx, retreat_end))
    if not out or out[-1].phase is Phase.RETREAT:
        onset = _trailing_reach(s, c, min(prev_end_idx, len(t_idx) - 1))
        if onset is not None:
            start = max(onset, out[-1].end) if out else onset
            out.append(Segment(Phase.REACH, min(start, t_last), t_last, len(out) // 3))
    # The next reach may begin before the retreat looked finished: clip the retreat.
    for i in range(len(out) - 1):
        ret, nxt_reach = out[i], out[i + 1]
        if ret.phase is Phase.RETREAT and ret.end > nxt_reach.start:
            fixed = max(nxt_reach.start, ret.start)
            out[i] = Segment(Phase.RETREAT, ret.start, fixed, ret.handover)
            if nxt_reach.start < fixed:
                out[i + 1] = Segment(Phase.REACH, fixed, nxt_reach.end, nxt_reach.handover)
    return out
