"""The ``gazebot`` method's cheap online trigger (the hook :meth:`GazebotSegmenter.trigger`).

The full analysis costs milliseconds, so the online detector first checks, once per
``online_period``, a necessary condition (loosened) of the rule that ends the current phase, on
the hands' mean positions per period: idle, the hands closed with the giver's hand moving;
reach, the hands stopped closing fast; transfer, the relative position left the held pose;
retreat, the giver's hand slowing or far. Only when it fires does the method run; a reach or
retreat still refreshes its end prediction every ``online_refresh``. Every factor is a named
field of :class:`~gazebot.core.phases.config.PhaseConfig` (``trigger_*``, ``configs/phases.yaml``).
"""

from __future__ import annotations

import math
from bisect import bisect_left
from collections import deque
from collections.abc import Sequence

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.filtering import vector_norm
from gazebot.core.phases.methods.base import OnlineState, TriggerMode
from gazebot.core.types import Phase

_COLUMNS = 12  # t, giver xyz, receiver xyz, relative xyz, distance, giver step
_STEP = 11  # the giver's step column: |giver - giver trigger_speed_baseline earlier|


def _nanmean2(a: Sequence[float], b: Sequence[float]) -> list[float]:
    """``np.nanmean([a, b], axis=0)`` of two 3-vectors: per coordinate the mean of the values
    that are not NaN, NaN if neither is (without numpy's all-NaN warning)."""
    out = []
    for u, w in zip(a, b, strict=True):
        known = [x for x in (float(u), float(w)) if not math.isnan(x)]
        out.append(sum(known) / len(known) if known else math.nan)
    return out


def _norm_at_least(v: Sequence[float], bar: float) -> bool:
    """``|v| >= bar`` for a 3-vector (the rules' :func:`vector_norm`; False for NaN)."""
    return vector_norm(np.asarray(v, dtype=float)) >= bar


def _dot_over_at_least(a: Sequence[float], b: Sequence[float], d: float, bar: float) -> bool:
    """``a . b / d >= bar`` for 3-vectors, ``d`` > 0 (False for NaN)."""
    return float(np.dot(np.asarray(a, dtype=float), np.asarray(b, dtype=float))) / d >= bar


def _search(times: list[float], x: float, lo: int, hi: int) -> int:
    """``np.searchsorted`` (side left) of ``x`` in the increasing ``times[lo:hi]``, as an
    index of ``times``: NaN sorts after every time, as numpy sorts it."""
    return hi if math.isnan(x) else bisect_left(times, x, lo, hi)


class _SuffixMax:
    """The largest value of one column over the rows from a first row to the newest, as the
    rows arrive and the first row moves forward (a phase's start, the window's start): a
    queue of the rows that may still be the largest (each smaller than the one before), so a
    period costs a few comparisons however long the span. Rows are numbered from the first
    ever kept, so dropping old rows does not move them."""

    def __init__(self) -> None:
        self._rows: deque[tuple[int, float]] = deque()  # (row, value), values decreasing
        self._first = self._end = -1  # the span [first, end) the queue covers

    def update(self, col: list[float], base: int, first: int, end: int) -> float:
        """Extend to rows ``[first, end)`` of the column ``col`` (its item i is row
        ``base + i``) and return the largest value that is not NaN, NaN if none."""
        a0, a_end = base + first, base + end
        q = self._rows
        if a0 < self._first or self._end < a0 or a_end < self._end:
            q.clear()  # the span moved back or skipped rows: start over from its first row
            self._end = a0
        for i in range(self._end, a_end):
            v = col[i - base]
            if math.isnan(v):
                continue  # (np.fmax passes over NaN)
            while q and q[-1][1] <= v:
                q.pop()
            q.append((i, v))
        while q and q[0][0] < a0:
            q.popleft()
        self._first, self._end = a0, a_end
        return q[0][1] if q else math.nan


def _fmax(values: list[float]) -> float:
    """The largest value that is not NaN (``np.fmax.reduce``), NaN if none."""
    return max((v for v in values if not math.isnan(v)), default=math.nan)


class GazebotTrigger:
    """Per-period mean positions of both hands, and the loosened rule of the current phase.

    The rows are kept in Python lists (a column each): a period appends one row and reads a
    few. The rules read maxima and means over the rows since a time that stays put while a
    phase lasts (its start, the floor): those are kept as running values, extended by each new
    row, and recomputed from the rows only when that time or the window's start moved (so a
    period reads the new row, not the whole window).

    Attributes:
        config: The settings (``trigger_*`` factors, ``online_window``, ``online_period``).
    """

    def __init__(self, config: PhaseConfig) -> None:
        self.config = config
        # Rows apart of the speed baseline (the giver's step column reads this far back).
        c = config
        period = max(c.online_period, 1e-3)
        baseline = c.trigger_speed_baseline / period
        self._k = max(1, int(round(baseline)))
        # The rules' bars and spans, which depend on the (frozen) settings alone: computed
        # once, by the same expressions the rules would evaluate each period.
        self._reach_recent = c.min_transfer + c.edge_guard + c.online_period  # s
        self._still_bar = c.trigger_still_factor * c.still_closing
        self._release_bar = c.trigger_distance_factor * c.release_distance
        self._far_bar = c.trigger_far_fraction * c.retreat_far_distance
        self._closed_bar = c.trigger_distance_factor * min(
            c.reach_confirm_distance, c.predict_distance
        )
        self._deep_bar = c.trigger_deep_fraction * c.min_approach
        self._own_bar = c.trigger_own_fraction * c.reach_confirm_distance
        # rows back to the start of the span the reach rule reads the speed over
        self._speed_rows = int((c.smoothing + c.edge_guard + c.trigger_speed_baseline) / period)
        self._step_time = self._k * period  # s a giver step spans
        self._onset_bar = c.trigger_distance_factor * c.reach_onset_speed
        # Sums of the positions seen this period and their counts, per hand: nothing is kept
        # per sample (tracking lost for long skips the periods' close, not the samples).
        self._sums = [0.0] * 6  # giver xyz, receiver xyz
        self._ng = self._nr = 0
        # The rows kept are items _s0.. of each column (times, giver means, receiver means,
        # relative positions, distances, giver steps: |giver - giver trigger_speed_baseline
        # earlier|); the relative position, distance and step are computed once per row. Item
        # i is row _base + i of all rows (old items are deleted in blocks).
        self._t: list[float] = []
        self._g: list[tuple[float, float, float]] = []
        self._r: list[tuple[float, float, float]] = []
        self._rel: list[tuple[float, float, float]] = []
        self._d: list[float] = []
        self._step: list[float] = []
        self._s0 = 0
        self._base = 0
        # Running values over the rows since a phase's start (or the floor):
        self._dmax = _SuffixMax()  # largest distance
        self._smax = _SuffixMax()  # largest giver step
        # (first row, end row) covered, the relative position's sums and their count
        self._held: tuple[int, int, list[float], int] = (-1, -1, [], 0)

    def add(self, g: Sequence[float], g_ok: bool, r: Sequence[float], r_ok: bool) -> None:
        """Add one sample's hand positions (``*_ok``: that hand was seen) to the period's sums."""
        a = self._sums
        if g_ok:
            x, y, z = g
            a[0] += x
            a[1] += y
            a[2] += z
            self._ng += 1
        if r_ok:
            x, y, z = r
            a[3] += x
            a[4] += y
            a[5] += z
            self._nr += 1

    def decide(self, now: float, state: OnlineState) -> TriggerMode:
        """Close the period: ``full`` if the next boundary may have passed, ``refresh`` if not
        but a reach is due for its ``online_refresh`` (a retreat's landing is dated from the
        speed profile the analysis sees: it runs in full), else ``skip``."""
        self._summarise(now)
        if self._boundary_possible(state):
            return "full"
        if now - state.last_full < self.config.online_refresh:
            return "skip"
        ph = state.phase
        return "refresh" if ph is Phase.REACH else "full" if ph is Phase.RETREAT else "skip"

    def _summarise(self, now: float) -> None:
        """Append the mean hand positions since the last period (NaN: none seen), their
        relative position, distance and the giver's step, and drop rows older than
        ``online_window``."""
        times = self._t
        cut = now - self.config.online_window
        s0, end = self._s0, len(times)
        while s0 < end and times[s0] < cut:
            s0 += 1
        if s0 >= 256 and 2 * s0 >= end:
            # (deleting a block now and then: the lists stay about a window long)
            for col in (times, self._g, self._r, self._rel, self._d, self._step):
                del col[:s0]
            self._base += s0
            s0, end = 0, end - s0
        self._s0 = s0
        nan = math.nan
        (gx, gy, gz, rx, ry, rz), ng, nr = self._sums, self._ng, self._nr
        gx, gy, gz = (gx / ng, gy / ng, gz / ng) if ng else (nan, nan, nan)
        rx, ry, rz = (rx / nr, ry / nr, rz / nr) if nr else (nan, nan, nan)
        self._sums = [0.0] * 6
        self._ng = self._nr = 0
        dx, dy, dz = rx - gx, ry - gy, rz - gz
        # (the sum in this order is what np.linalg.norm(rel, axis=1) computes; a test pins it)
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        step = nan
        if end - self._k >= s0:
            px, py, pz = self._g[end - self._k]
            sx, sy, sz = gx - px, gy - py, gz - pz
            step = math.sqrt(sx * sx + sy * sy + sz * sz)
        times.append(now)
        self._g.append((gx, gy, gz))
        self._r.append((rx, ry, rz))
        self._rel.append((dx, dy, dz))
        self._d.append(d)
        self._step.append(step)

    def rows(self) -> np.ndarray:
        """The per-period rows kept: ``[t, giver xyz, receiver xyz, relative xyz, distance,
        giver step]`` (a new array; the step is NaN for a row with no row
        ``trigger_speed_baseline`` before it)."""
        s0 = self._s0
        out = np.empty((len(self._t) - s0, _COLUMNS))
        out[:, 0] = self._t[s0:]
        out[:, 1:4] = self._g[s0:]
        out[:, 4:7] = self._r[s0:]
        out[:, 7:10] = self._rel[s0:]
        out[:, 10] = self._d[s0:]
        out[:, _STEP] = self._step[s0:]
        return out

    def _boundary_possible(self, state: OnlineState) -> bool:
        """A necessary condition of the rule that ends the current phase, on the per-period
        means (loose: ``trigger_distance_factor`` x its distances, so it fires before the rule
        can)."""
        ph = state.phase
        times = self._t
        s0, s1 = self._s0, len(times)
        if s1 - s0 < 3 or not state.tracking:
            return True
        d_last = self._d[-1]
        if not math.isfinite(d_last):
            return True
        if ph in (Phase.IDLE, Phase.DONE):
            return self._reach_possible(d_last, state.floor)
        if ph is Phase.REACH:
            # A transfer needs the approach to have stopped, an aborted reach the hands apart:
            # either way the hands are no longer closing fast.
            since = times[-1] - self._reach_recent
            recent = _fmax(self._d[_search(times, since, s0, s1) : s1])
            return recent - d_last <= self._still_bar
        first = _search(times, state.phase_start, s0, s1)
        if ph is Phase.TRANSFER:
            # A release moves the hands' relative position off the held pose.
            mean = self._held_mean(first)
            if mean is None:
                return True
            # (the last two periods' mean: the analysis trusts nothing newer than edge_guard)
            n0, n1, n2 = _nanmean2(self._rel[-2], self._rel[-1])
            m0, m1, m2 = mean
            return _norm_at_least((n0 - m0, n1 - m1, n2 - m2), self._release_bar)
        if ph is Phase.RETREAT:
            if state.joined_late:
                return True
            # The retreat ends landing (slowing down), at rest or far away.
            k = self._k
            if s1 - first <= k:
                return True
            x0, y0, z0 = self._g[first]
            x1, y1, z1 = self._g[-1]
            fin = math.isfinite
            if not (fin(x0) and fin(y0) and fin(z0) and fin(x1) and fin(y1) and fin(z1)):
                return True
            if _norm_at_least((x1 - x0, y1 - y0, z1 - z0), self._far_bar):
                return True
            last = self._step[-1]
            if not math.isfinite(last):
                return True
            # (the steps within the retreat: rows at least k after its first)
            return last <= self.config.trigger_landing_fraction * self._smax.update(
                self._step, self._base, first + k, s1
            )
        return True

    def _held_mean(self, first: int) -> list[float] | None:
        """The mean relative position over the rows from item ``first`` on where it is
        known (numpy's ``mean(axis=0)``: the rows summed in order), ``None`` if fewer than two;
        a running sum extended by the rows since the last call, or recomputed."""
        end = len(self._t)
        a0, a_end = self._base + first, self._base + end
        k0, k_end, sums, count = self._held
        if k0 != a0 or k_end > a_end:
            k_end, sums, count = a0, [0.0, 0.0, 0.0], 0
        for x, y, z in self._rel[k_end - self._base : end]:
            if math.isfinite(x) and math.isfinite(y) and math.isfinite(z):
                if count:
                    sums = [sums[0] + x, sums[1] + y, sums[2] + z]
                else:
                    sums = [x, y, z]
                count += 1
        self._held = (a0, a_end, sums, count)
        if count < 2:
            return None
        return [v / count for v in sums]

    def _reach_possible(self, d_last: float, floor: float) -> bool:
        """A reach (or a transfer) needs the hands closer than they were since the last phase
        began and the giver's hand moving since they were farthest."""
        k = self._k
        times = self._t
        s0, end = self._s0, len(times)
        first = _search(times, floor - self.config.online_period, s0, end)
        if end - first <= k:
            return False
        d_max = self._dmax.update(self._d, self._base, first, end)
        closed = d_max - d_last
        # (the predictive rule confirms a reach from predict_distance of the giver's own travel;
        # the sequential one, in practice, past 1.2 cm: every fidget fits a cubic start up to
        # its midpoint, so it waits for more than half the largest fidget)
        if not closed >= self._closed_bar:
            return False
        i_max = self._d.index(d_max, first)  # np.nanargmax: the first largest
        deep = closed >= self._deep_bar
        if not deep:
            # (the giver's own share of the closing, read only when the dip is not deep)
            x1, y1, z1 = self._g[-1]
            x0, y0, z0 = self._g[i_max]
            moved = (x1 - x0, y1 - y0, z1 - z0)
            if not _dot_over_at_least(moved, self._rel[-1], max(d_last, 1e-9), self._own_bar):
                return False  # only the receiver came closer: no reach of the giver's yet
        # The giver's hand moving fast: since the hands were farthest for a deep dip, else
        # within the window the rule reads (smoothing, before the edge guard).
        recent = end - 1 - self._speed_rows
        g_first = max(i_max - k, s0 if deep else recent, s0)
        if end - g_first <= k:
            return True
        # The speeds over k rows from g_first on are the steps of the rows k after it (each
        # row's step is from the row k before it, there when the row arrived), divided by the
        # same positive number: the largest speed is the largest step's.
        v_max = _fmax(self._step[g_first + k : end]) / self._step_time
        return bool(max(0.0, v_max) >= self._onset_bar)
