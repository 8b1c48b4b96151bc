"""The ``gazebot`` method's cheap online trigger (the hook :meth:`GazebotSegmenter.trigger`).

The full analysis costs milliseconds, so the online detector first checks, once per
``online_period``, a necessary condition (loosened) of the rule that ends the current phase, on
the hands' mean positions per period: idle, the hands closed with the giver's hand moving;
reach, the hands stopped closing fast; transfer, the relative position left the held pose;
retreat, the giver's hand slowing or far. Only when it fires does the method run; a reach or
retreat still refreshes its end prediction every ``online_refresh``. Every factor is a named
field of :class:`~gazebot.phases.config.PhaseConfig` (``trigger_*``, ``configs/phases.yaml``).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

import numpy as np

from gazebot.phases.config import PhaseConfig
from gazebot.phases.filtering import nanmax, vector_norm
from gazebot.phases.methods.base import OnlineState, TriggerMode
from gazebot.types import Phase

_COLUMNS = 12  # t, giver xyz, receiver xyz, relative xyz, distance, giver step
_STEP = 11  # the giver's step column: |giver - giver trigger_speed_baseline earlier|


def _nanmean2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.nanmean([a, b], axis=0)`` of two 3-vectors: per coordinate the sum of the values
    that are not NaN (NaN counted as 0) over their count, NaN if none (numpy's arithmetic,
    without its generic machinery and warning)."""
    out = []
    for u, w in zip(a.tolist(), b.tolist(), strict=True):
        u_ok, w_ok = u == u, w == w
        n = u_ok + w_ok
        out.append(((u if u_ok else 0.0) + (w if w_ok else 0.0)) / n if n else math.nan)
    return np.array(out)


class _SuffixMax:
    """The largest value of one column over the rows from a first row to the newest, as the
    rows arrive and the first row moves forward (a phase's start, the window's start): a
    queue of the rows that may still be the largest (each smaller than the one before), so a
    period costs a few comparisons however long the span. Rows are numbered from the first
    ever kept, so the buffer's compaction does not move them."""

    def __init__(self) -> None:
        self._rows: deque[tuple[int, float]] = deque()  # (row, value), values decreasing
        self._first = self._end = -1  # the span [first, end) the queue covers

    def update(self, buf: np.ndarray, base: int, first: int, end: int, col: int) -> float:
        """Extend to buffer rows ``[first, end)`` of column ``col`` (buffer row i is row
        ``base + i``) and return the largest value that is not NaN, NaN if none."""
        a0, a_end = base + first, base + end
        q = self._rows
        if a0 < self._first or self._end < a0 or a_end < self._end:
            q.clear()  # the span moved back or skipped rows: start over from its first row
            self._end = a0
        new = buf[self._end - base : end, col].tolist()
        for i, v in enumerate(new, start=self._end):
            if v != v:
                continue  # (np.fmax passes over NaN)
            while q and q[-1][1] <= v:
                q.pop()
            q.append((i, v))
        while q and q[0][0] < a0:
            q.popleft()
        self._first, self._end = a0, a_end
        return q[0][1] if q else math.nan


class GazebotTrigger:
    """Per-period mean positions of both hands, and the loosened rule of the current phase.

    The rules read maxima and means over the rows since a time that stays put while a phase
    lasts (its start, the floor): those are kept as running values, extended by each new row,
    and recomputed from the rows only when that time or the window's start moved (so a period
    costs a few float operations, not a pass over the window).

    Attributes:
        config: The settings (``trigger_*`` factors, ``online_window``, ``online_period``).
    """

    def __init__(self, config: PhaseConfig) -> None:
        self.config = config
        # Rows apart of the speed baseline (the giver's step column reads this far back).
        baseline = config.trigger_speed_baseline / max(config.online_period, 1e-3)
        self._k = max(1, int(round(baseline)))
        # Sums of the positions seen this period (giver xyz, receiver xyz) and their counts, in
        # plain floats: a sample costs a few additions, not numpy calls.
        self._acc = [0.0] * 6
        self._acc_n = [0, 0]
        # rows [t, giver xyz, receiver xyz, relative xyz, distance, giver step] in
        # _sum[_s0:_s1] (grown and compacted in place); the relative position, distance and
        # step are computed once per row. Row i of the buffer is row _base + i of all rows.
        self._sum = np.empty((64, _COLUMNS))
        self._s0 = self._s1 = 0
        self._base = 0
        self._d_last = math.nan  # the distance of the last row
        # Running values over the rows since a phase's start (or the floor):
        self._dmax = _SuffixMax()  # largest distance
        self._smax = _SuffixMax()  # largest giver step
        # (first row, end row) covered, the relative position's sums and their count
        self._held: tuple[int, int, list[float], int] = (-1, -1, [], 0)

    def add(self, g: Sequence[float], g_ok: bool, r: Sequence[float], r_ok: bool) -> None:
        """Accumulate one sample's hand positions (``*_ok``: that hand was seen)."""
        acc = self._acc
        if g_ok:
            x, y, z = g
            acc[0] += x
            acc[1] += y
            acc[2] += z
            self._acc_n[0] += 1
        if r_ok:
            x, y, z = r
            acc[3] += x
            acc[4] += y
            acc[5] += z
            self._acc_n[1] += 1

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
        buf = self._sum
        cut = now - self.config.online_window
        while self._s0 < self._s1 and buf[self._s0, 0] < cut:
            self._s0 += 1
        if self._s1 == buf.shape[0]:
            m = self._s1 - self._s0
            if 2 * m > buf.shape[0]:
                self._sum = np.empty((2 * buf.shape[0], _COLUMNS))
            self._sum[:m] = buf[self._s0 : self._s1]
            buf, self._base = self._sum, self._base + self._s0
            self._s0, self._s1 = 0, m
        a = self._acc
        ng, nr = self._acc_n
        nan = math.nan
        gx, gy, gz = (a[0] / ng, a[1] / ng, a[2] / ng) if ng else (nan, nan, nan)
        rx, ry, rz = (a[3] / nr, a[4] / nr, a[5] / nr) if nr else (nan, nan, nan)
        dx, dy, dz = rx - gx, ry - gy, rz - gz
        # (the sum in this order is what np.linalg.norm(rel, axis=1) computes; a test pins it)
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        step = nan
        if self._s1 - self._k >= self._s0:
            px, py, pz = buf[self._s1 - self._k, 1:4].tolist()
            sx, sy, sz = gx - px, gy - py, gz - pz
            step = math.sqrt(sx * sx + sy * sy + sz * sz)
        buf[self._s1] = (now, gx, gy, gz, rx, ry, rz, dx, dy, dz, d, step)
        self._s1 += 1
        self._d_last = d
        self._acc = [0.0] * 6
        self._acc_n = [0, 0]

    def rows(self) -> np.ndarray:
        """The per-period rows kept: ``[t, giver xyz, receiver xyz, relative xyz, distance,
        giver step]`` (a view, valid until the next :meth:`decide`; the step is NaN for a row
        with no row ``trigger_speed_baseline`` before it)."""
        return self._sum[self._s0 : self._s1]

    def _running_max(self, kept: _SuffixMax, first: int, col: int) -> float:
        """The largest value that is not NaN (NaN if none) of column ``col`` from buffer row
        ``first`` on (what ``np.fmax.reduce`` gives), from ``kept``."""
        return kept.update(self._sum, self._base, first, self._s1, col)

    def _boundary_possible(self, state: OnlineState) -> bool:
        """A necessary condition of the rule that ends the current phase, on the per-period
        means (loose: ``trigger_distance_factor`` x its distances, so it fires before the rule
        can)."""
        c = self.config
        ph = state.phase
        s0, s1 = self._s0, self._s1
        if s1 - s0 < 3 or not state.tracking:
            return True
        buf = self._sum
        d_last = self._d_last
        if not math.isfinite(d_last):
            return True
        ts = buf[s0:s1, 0]
        if ph in (Phase.IDLE, Phase.DONE):
            return self._reach_possible(ts, d_last, state.floor)
        if ph is Phase.REACH:
            # A transfer needs the approach to have stopped, an aborted reach the hands apart:
            # either way the hands are no longer closing fast.
            since = float(ts[-1]) - (c.min_transfer + c.edge_guard + c.online_period)
            recent = buf[s0 + int(ts.searchsorted(since)) : s1, 10]  # (ts increases)
            return float(nanmax(recent)) - d_last <= c.trigger_still_factor * c.still_closing
        first = s0 + int(ts.searchsorted(state.phase_start))  # (ts increases)
        if ph is Phase.TRANSFER:
            # A release moves the hands' relative position off the held pose.
            mean = self._held_mean(first)
            if mean is None:
                return True
            # (the last two periods' mean: the analysis trusts nothing newer than edge_guard)
            rel = buf[s1 - 2 : s1, 7:10]
            off = vector_norm(_nanmean2(rel[0], rel[1]) - np.array(mean))
            return off >= c.trigger_distance_factor * c.release_distance
        if ph is Phase.RETREAT:
            if state.joined_late:
                return True
            # The retreat ends landing (slowing down), at rest or far away.
            k = self._k
            if s1 - first <= k:
                return True
            g0, g1 = buf[first, 1:4], buf[s1 - 1, 1:4]
            if not all(math.isfinite(v) for v in g0.tolist() + g1.tolist()):
                return True
            far = c.trigger_far_fraction * c.retreat_far_distance
            if vector_norm(g1 - g0) >= far:
                return True
            last = float(buf[s1 - 1, _STEP])
            if not math.isfinite(last):
                return True
            # (the steps within the retreat: rows at least k after its first)
            return last <= c.trigger_landing_fraction * self._running_max(
                self._smax, first + k, _STEP
            )
        return True

    def _held_mean(self, first: int) -> list[float] | None:
        """The mean relative position over the rows from buffer row ``first`` on where it is
        known (numpy's ``mean(axis=0)``: the rows summed in order), ``None`` if fewer than two;
        a running sum extended by the rows since the last call, or recomputed."""
        a0, end = self._base + first, self._base + self._s1
        k0, k_end, sums, count = self._held
        if k0 != a0 or k_end > end:
            k_end, sums, count = a0, [0.0, 0.0, 0.0], 0
        for x, y, z in self._sum[k_end - self._base : self._s1, 7:10].tolist():
            if x == x and y == y and z == z and abs(x) + abs(y) + abs(z) < math.inf:
                if count:
                    sums = [sums[0] + x, sums[1] + y, sums[2] + z]
                else:
                    sums = [x, y, z]
                count += 1
        self._held = (a0, end, sums, count)
        if count < 2:
            return None
        return [v / count for v in sums]

    def _reach_possible(self, ts: np.ndarray, d_last: float, floor: float) -> bool:
        """A reach (or a transfer) needs the hands closer than they were since the last phase
        began and the giver's hand moving since they were farthest."""
        c = self.config
        k = self._k
        loose = c.trigger_distance_factor
        first = int(ts.searchsorted(floor - c.online_period))  # (ts increases)
        if ts.shape[0] - first <= k:
            return False
        d_max = self._running_max(self._dmax, self._s0 + first, 10)
        closed = d_max - d_last
        # (the predictive rule confirms a reach from predict_distance of the giver's own travel;
        # the sequential one, in practice, past 1.2 cm: every fidget fits a cubic start up to
        # its midpoint, so it waits for more than half the largest fidget)
        if not closed >= loose * min(c.reach_confirm_distance, c.predict_distance):
            return False
        rows = self._sum[self._s0 : self._s1]
        g = rows[:, 1:4]
        rel = rows[:, 7:10]
        d = rows[:, 10]
        da = d[first:]
        i_max = first + int(np.argmax(da == d_max))  # np.nanargmax: the first largest
        deep = closed >= c.trigger_deep_fraction * c.min_approach
        if not deep:
            # (the giver's own share of the closing, read only when the dip is not deep)
            own = float(np.dot(g[-1] - g[i_max], rel[-1])) / max(d_last, 1e-9)
            if not own >= c.trigger_own_fraction * c.reach_confirm_distance:
                return False  # only the receiver came closer: no reach of the giver's yet
        # The giver's hand moving fast: since the hands were farthest for a deep dip, else
        # within the window the rule reads (smoothing, before the edge guard).
        span = (c.smoothing + c.edge_guard + c.trigger_speed_baseline) / max(c.online_period, 1e-3)
        recent = ts.shape[0] - 1 - int(span)
        gm = g[max(i_max - k, 0 if deep else recent, 0) :]
        if gm.shape[0] <= k:
            return True
        v = np.linalg.norm(gm[k:] - gm[:-k], axis=1) / (k * max(c.online_period, 1e-3))
        return bool(nanmax(v, initial=0.0) >= loose * c.reach_onset_speed)
