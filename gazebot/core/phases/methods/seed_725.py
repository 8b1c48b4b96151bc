"""``seed-7.2.5``: the seed's annotation rule, exactly as published.

Dissertation section 7.2.5: "the 'transfer' phase corresponds to the portion of the handover
where the distance between the giver's and receiver's hands is within 20cm of the minimum
distance, and their relative velocity is less than 15cm/s."

Per handover, the transfer is the longest run of samples where the hands are within
``transfer_distance_margin`` (0.20 m) of that handover's minimum distance and their relative
speed is under ``transfer_speed_max`` (0.15 m/s). The seed names no speed filter: the relative
speed is ``|p_rel(t + h) - p_rel(t - h)| / 2h`` with ``h = seed_speed_half_window`` (0.05 s) on
the raw samples, linearly interpolated (our choice). The reach is the motion before the transfer
and the retreat the motion after it. Nothing else is added.

The seed split its recordings into single handovers by hand. Here each handover is a region
around a local minimum ``m`` of the hands' distance where it stays within ``m + 0.20 m``,
bounded on at least one side by a sample farther than that (the hands came from, or went,
farther away); regions are taken from the smallest minimum up and never overlap. Consecutive
handovers are split at the largest distance between them; the first reach starts at the first
sample and the last retreat ends at the last one. Missing samples are skipped.
"""

from __future__ import annotations

import numpy as np

from gazebot.core.phases.methods.base import Segmenter, central_speed
from gazebot.core.phases.segment import Segment
from gazebot.core.phases.trajectory import Trajectory
from gazebot.core.types import Phase


def handover_windows(d: np.ndarray, margin: float) -> list[tuple[int, int]]:
    """Inclusive index ranges ``[a, b]`` of the handover regions of ``d`` (time order)."""
    n = d.shape[0]
    free = np.isfinite(d)
    taken = ~free  # missing samples never start a region
    out: list[tuple[int, int]] = []
    work = np.where(free, d, np.inf)
    while True:
        cand = np.where(taken, np.inf, work)
        i = int(np.argmin(cand))
        if not np.isfinite(cand[i]):
            break
        limit = d[i] + margin
        a = i
        while a > 0 and not taken[a - 1] and d[a - 1] <= limit:
            a -= 1
        b = i
        while b < n - 1 and not taken[b + 1] and d[b + 1] <= limit:
            b += 1
        left_far = a > 0 and free[a - 1] and d[a - 1] > limit
        right_far = b < n - 1 and free[b + 1] and d[b + 1] > limit
        touches = (a > 0 and taken[a - 1] and free[a - 1]) or (
            b < n - 1 and taken[b + 1] and free[b + 1]
        )
        taken[a : b + 1] = True
        if (left_far or right_far) and not touches:
            out.append((a, b))
    return sorted(out)


def longest_run(mask: np.ndarray) -> tuple[int, int] | None:
    """The first longest True run of ``mask`` as an inclusive range, or ``None``."""
    best: tuple[int, int] | None = None
    start = -1
    for i, v in enumerate(mask.tolist() + [False]):
        if v and start < 0:
            start = i
        elif not v and start >= 0:
            if best is None or (i - 1 - start) > (best[1] - best[0]):
                best = (start, i - 1)
            start = -1
    return best


class Seed725Segmenter(Segmenter):
    """The seed's section 7.2.5 rule (see the module docstring)."""

    name = "seed-7.2.5"

    def segment_sorted(self, trajectory: Trajectory, partial: bool = False) -> list[Segment]:
        """Segments of a time-sorted trajectory by the seed's section 7.2.5 rule (see
        :meth:`Segmenter.segment_sorted`)."""
        c = self.config
        ok = np.isfinite(trajectory.giver_hand).all(axis=1) & np.isfinite(
            trajectory.receiver_hand
        ).all(axis=1)
        t = trajectory.t[ok]
        if t.shape[0] < 3:
            return []
        rel = trajectory.receiver_hand[ok] - trajectory.giver_hand[ok]
        d = np.linalg.norm(rel, axis=1)
        v = central_speed(t, rel, c.seed_speed_half_window)
        transfers: list[tuple[int, int, int, int]] = []
        for a, b in handover_windows(d, c.transfer_distance_margin):
            slow = np.isfinite(v[a : b + 1]) & (v[a : b + 1] < c.transfer_speed_max)
            run = longest_run(slow)
            if run is not None:
                transfers.append((a, b, a + run[0], a + run[1]))
        out: list[Segment] = []
        last = t.shape[0] - 1
        for k, (_, b, i0, i1) in enumerate(transfers):
            start = float(t[0]) if k == 0 else out[-1].end
            if k + 1 < len(transfers):
                a_next = transfers[k + 1][0]
                split = b + int(np.argmax(d[b : a_next + 1]))
                end = float(t[max(split, i1)])
            else:
                end = float(t[last])
            out.append(Segment(Phase.REACH, start, float(t[i0]), k))
            out.append(Segment(Phase.TRANSFER, float(t[i0]), float(t[i1]), k, open=i1 == last))
            if i1 < last:
                out.append(Segment(Phase.RETREAT, float(t[i1]), end, k, open=end >= t[last]))
        return out
