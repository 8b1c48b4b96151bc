"""The gazebot trigger as it was before its rows were kept in plain floats (issue 19): numpy
sums per sample, the relative positions and distances of the whole window recomputed every
period, boolean masks for the time windows. The detector with the current trigger must emit
exactly what it emits with this one. Tests only."""

from __future__ import annotations

import math

import numpy as np

from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.methods.base import OnlineState, TriggerMode
from gazebot.core.types import Phase


class ReferenceTrigger:
    """Per-period mean positions of both hands, and the loosened rule of the current phase.

    Attributes:
        config: The settings (``trigger_*`` factors, ``online_window``, ``online_period``).
    """

    def __init__(self, config: PhaseConfig) -> None:
        self.config = config
        self._acc = np.zeros(6)
        self._acc_n = np.zeros(2)
        # rows [t, giver xyz, receiver xyz] in _sum[_s0:_s1] (grown and compacted in place)
        self._sum = np.empty((64, 7))
        self._s0 = self._s1 = 0

    def add(self, g: np.ndarray, g_ok: bool, r: np.ndarray, r_ok: bool) -> None:
        """Accumulate one sample's hand positions (``*_ok``: that hand was seen)."""
        if g_ok:
            self._acc[:3] += g
            self._acc_n[0] += 1
        if r_ok:
            self._acc[3:] += r
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
        return {Phase.REACH: "refresh", Phase.RETREAT: "full"}.get(state.phase, "skip")  # type: ignore[return-value]

    def _summarise(self, now: float) -> None:
        """Append the mean hand positions since the last period (NaN: none seen) and drop
        rows older than ``online_window``."""
        c = self.config
        n = self._acc_n
        buf = self._sum
        while self._s0 < self._s1 and buf[self._s0, 0] < now - c.online_window:
            self._s0 += 1
        if self._s1 == buf.shape[0]:
            m = self._s1 - self._s0
            if 2 * m > buf.shape[0]:
                self._sum = np.empty((2 * buf.shape[0], 7))
            self._sum[:m] = buf[self._s0 : self._s1]
            buf, self._s0, self._s1 = self._sum, 0, m
        row = buf[self._s1]
        row[0] = now
        row[1:4] = self._acc[:3] / n[0] if n[0] else np.nan
        row[4:] = self._acc[3:] / n[1] if n[1] else np.nan
        self._s1 += 1
        self._acc[:] = 0.0
        n[:] = 0.0

    def _boundary_possible(self, state: OnlineState) -> bool:
        """A necessary condition of the rule that ends the current phase, on the per-period
        means (loose: ``trigger_distance_factor`` x its distances, so it fires before the rule
        can)."""
        c = self.config
        ph = state.phase
        if self._s1 - self._s0 < 3 or not state.tracking:
            return True
        rows = self._sum[self._s0 : self._s1]
        ts = rows[:, 0]
        g = rows[:, 1:4]
        rel = rows[:, 4:] - g
        d = np.linalg.norm(rel, axis=1)
        if not math.isfinite(d[-1]):
            return True
        loose = c.trigger_distance_factor
        k = max(1, int(round(c.trigger_speed_baseline / max(c.online_period, 1e-3))))
        if ph in (Phase.IDLE, Phase.DONE):
            return self._reach_possible(ts, g, rel, d, k, state.floor)
        if ph is Phase.REACH:
            # A transfer needs the approach to have stopped, an aborted reach the hands apart:
            # either way the hands are no longer closing fast.
            recent = d[ts >= ts[-1] - (c.min_transfer + c.edge_guard + c.online_period)]
            return float(np.nanmax(recent)) - d[-1] <= c.trigger_still_factor * c.still_closing
        since = ts >= state.phase_start
        if ph is Phase.TRANSFER:
            # A release moves the hands' relative position off the held pose.
            held = rel[since]
            held = held[np.isfinite(held).all(axis=1)]
            if held.shape[0] < 2:
                return True
            # (the last two periods' mean: the analysis trusts nothing newer than edge_guard)
            off = float(np.linalg.norm(np.nanmean(rel[-2:], axis=0) - held.mean(axis=0)))
            return off >= loose * c.release_distance
        if ph is Phase.RETREAT:
            if state.joined_late:
                return True
            # The retreat ends landing (slowing down), at rest or far away.
            gs = g[since]
            if gs.shape[0] <= k or not np.isfinite(gs[[0, -1]]).all():
                return True
            step = np.linalg.norm(gs[k:] - gs[:-k], axis=1)
            far = c.trigger_far_fraction * c.retreat_far_distance
            if float(np.linalg.norm(gs[-1] - gs[0])) >= far:
                return True
            if not math.isfinite(float(step[-1])):
                return True
            return bool(step[-1] <= c.trigger_landing_fraction * np.nanmax(step))
        return True

    def _reach_possible(
        self, ts: np.ndarray, g: np.ndarray, rel: np.ndarray, d: np.ndarray, k: int, floor: float
    ) -> bool:
        """A reach (or a transfer) needs the hands closer than they were since the last phase
        began and the giver's hand moving since they were farthest."""
        c = self.config
        loose = c.trigger_distance_factor
        after = np.flatnonzero(ts >= floor - c.online_period)
        if after.size <= k:
            return False
        da = d[after[0] :]
        closed = float(np.nanmax(da)) - d[-1]
        # (the predictive rule confirms a reach from predict_distance of the giver's own travel)
        if not closed >= loose * min(c.reach_confirm_distance, c.predict_distance):
            return False
        i_max = after[0] + int(np.nanargmax(da))
        own = float(np.dot(g[-1] - g[i_max], rel[-1])) / max(float(d[-1]), 1e-9)
        deep = closed >= c.trigger_deep_fraction * c.min_approach
        if not deep and not own >= c.trigger_own_fraction * c.reach_confirm_distance:
            return False  # only the receiver came closer: no reach of the giver's yet
        # The giver's hand moving fast: since the hands were farthest for a deep dip, else
        # within the window the rule reads (smoothing, before the edge guard).
        span = (c.smoothing + c.edge_guard + c.trigger_speed_baseline) / max(c.online_period, 1e-3)
        recent = ts.shape[0] - 1 - int(span)
        gm = g[max(i_max - k, 0 if deep else recent, 0) :]
        if gm.shape[0] <= k:
            return True
        v = np.linalg.norm(gm[k:] - gm[:-k], axis=1) / (k * c.online_period)
        return bool(np.nanmax(v, initial=0.0) >= loose * c.reach_onset_speed)
