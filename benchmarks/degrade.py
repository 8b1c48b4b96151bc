"""Degraded copies of a recording, as the held-out checks make them (issues 20 and 33)."""

from __future__ import annotations

import numpy as np

from gazebot.core.phases import Trajectory

KINDS = ("30hz", "nan", "noise", "offset")


def degraded(traj: Trajectory, how: str, rng: np.random.Generator) -> Trajectory:
    """A copy of ``traj``: resampled to 30 Hz (``"30hz"``), NaN bursts (``"nan"``: 4 per hand,
    50-200 ms), 5 mm of noise (``"noise"``), each hand frame moved 6 cm in a random direction
    (``"offset"``), or all four in that order (``"all"``)."""
    t, g, r = traj.t.copy(), traj.giver_hand.copy(), traj.receiver_hand.copy()
    for kind in KINDS if how == "all" else (how,):
        if kind == "30hz":
            step = max(1, int(round((1 / 30) / np.median(np.diff(t)))))
            t, g, r = t[::step], g[::step], r[::step]
        elif kind == "nan":
            for a in (g, r):
                for x in rng.uniform(t[0], t[-1], 4):
                    a[(t >= x) & (t < x + rng.uniform(0.05, 0.2))] = np.nan
        elif kind == "noise":
            g += rng.normal(0, 0.005, g.shape)
            r += rng.normal(0, 0.005, r.shape)
        elif kind == "offset":
            for a in (g, r):
                way = rng.normal(size=3)
                a += 0.06 * way / np.linalg.norm(way)
        else:
            raise ValueError(f"degraded: how must be one of {KINDS + ('all',)}, got {how!r}")
    return Trajectory(t, g, r)
