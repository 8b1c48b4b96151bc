"""``seed-4.4.3``: the seed's split of a giving motion, exactly as published.

Dissertation section 4.4.3: "The reach phase begins at the time instant after which the
distance from the starting position becomes greater than d_1 x d_max. The reach phase ends (and
the transfer phase begins) when the speed drops below v_1 x v_max. The transfer phase ends (and
the retreat phase begins) when the speed goes below -v_1 x v_max. The retreat phase ends when
the distance from the starting position becomes less than d_1 x d_max." with d_1 = 0.41 and
v_1 = 0.43.

One hand, the giver's: ``D(t) = |p(t) - p(t_0)|`` from its first sample, ``d_max = max D``; the
signed speed is ``dD/dt``, as ``(D(t + h) - D(t - h)) / 2h`` with ``h = seed_speed_half_window``
(the seed names no filter; our choice), ``v_max`` its maximum. "Drops below" needs the speed to
have been above ``v_1 v_max`` first (it starts at zero). The seed splits single giving motions:
one handover per recording; a boundary never reached leaves its phase open to the data end.
Missing samples are skipped.

Our one addition (not in the seed): a giving motion moves the hand at least
``seed_min_motion`` (0.10 m) from its start. The published thresholds are fractions of the
recording's own maxima, so on a hand that never moved ``d_max`` is the marker noise and the
rule splits noise into phantom phases (three segments on a still hand with 1 mm of noise);
such a recording has no giving motion and gives no segments.
"""

from __future__ import annotations

import numpy as np

from gazebot.core.phases.methods.base import Segmenter
from gazebot.core.phases.segment import Segment
from gazebot.core.phases.trajectory import Trajectory
from gazebot.core.types import Phase


def signed_speed(t: np.ndarray, x: np.ndarray, half: float) -> np.ndarray:
    """``(x(t + half) - x(t - half)) / 2 half`` with ``x`` linearly interpolated (NaN outside)."""
    out = np.full(t.shape[0], np.nan)
    if t.shape[0] < 2:
        return out
    lo, hi = t - half, t + half
    inside = (lo >= t[0] - 1e-9) & (hi <= t[-1] + 1e-9)
    out[inside] = (np.interp(hi, t, x) - np.interp(lo, t, x))[inside] / (2.0 * half)
    return out


class Seed443Segmenter(Segmenter):
    """The seed's section 4.4.3 split (see the module docstring)."""

    name = "seed-4.4.3"

    def segment_sorted(self, trajectory: Trajectory, partial: bool = False) -> list[Segment]:
        """Segments of a time-sorted trajectory by the seed's section 4.4.3 split (see
        :meth:`Segmenter.segment_sorted`)."""
        c = self.config
        ok = np.isfinite(trajectory.giver_hand).all(axis=1)
        t = trajectory.t[ok]
        if t.shape[0] < 3:
            return []
        p = trajectory.giver_hand[ok]
        dist = np.linalg.norm(p - p[0], axis=1)
        v = signed_speed(t, dist, c.seed_speed_half_window)
        if not float(dist.max()) >= c.seed_min_motion:
            return []  # no giving motion (our addition, see the module docstring)
        d_lim = c.seed_d1 * float(dist.max())
        v_lim = c.seed_v1 * float(np.nanmax(v, initial=0.0))
        if not d_lim > 0 or not v_lim > 0:
            return []
        last = t.shape[0] - 1

        def first(mask: np.ndarray, after: int) -> int | None:
            idx = np.flatnonzero(mask[after:])
            return after + int(idx[0]) if idx.size else None

        i_reach = first(dist > d_lim, 0)
        if i_reach is None:
            return []
        fast = first(v > v_lim, i_reach)
        i_transfer = None if fast is None else first(v < v_lim, fast)
        if i_transfer is None:
            return [Segment(Phase.REACH, float(t[i_reach]), float(t[last]), 0, open=True)]
        out = [Segment(Phase.REACH, float(t[i_reach]), float(t[i_transfer]), 0)]
        i_retreat = first(v < -v_lim, i_transfer)
        if i_retreat is None:
            out.append(Segment(Phase.TRANSFER, float(t[i_transfer]), float(t[last]), 0, open=True))
            return out
        out.append(Segment(Phase.TRANSFER, float(t[i_transfer]), float(t[i_retreat]), 0))
        i_done = first(dist < d_lim, i_retreat)
        end = last if i_done is None else i_done
        out.append(
            Segment(Phase.RETREAT, float(t[i_retreat]), float(t[end]), 0, open=i_done is None)
        )
        return out
