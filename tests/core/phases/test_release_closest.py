"""``rules.release.transfer_end``: a coupled hold is not released while the hands still close
in, however the parting's back-dating reads: the release is not before the hands' distance was
last at its minimum."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline

from gazebot.core.phases import PhaseConfig, segment
from gazebot.core.phases.trajectory import Trajectory
from gazebot.core.types import Phase

CLOSEST = 3.4  # s, when the hands are nearest: the giver lets go there
D_MIN = 0.3226  # m, between the hand frames (a suit's segment origins)


def _careful_pitcher(rate: float = 120.0) -> Trajectory:
    """A pair carrying a full pitcher on while the hands creep closer for 1.2 s (closing at
    12 down to 0 cm/s, the pair speeding up to 0.28 m/s), nearest at ``CLOSEST``; then the
    giver withdraws, the hands parting at a constant 1.5 m/s^2 (faster than a minimum-jerk
    start: its back-dating alone reads the release 0.1 s early)."""
    t = np.arange(0.0, 6.0, 1.0 / rate)
    knots = [0.0, 1.0, 2.2, CLOSEST, CLOSEST + 0.2, 4.4, 6.0]
    d = CubicHermiteSpline(knots, [0.9, 0.9, D_MIN + 0.072, D_MIN, D_MIN + 0.03, 0.8, 0.8],
                           [0.0, 0.0, -0.12, 0.0, 0.3, 0.0, 0.0])(t)
    # The pair's common motion along y: from rest at 2.2 s up to 0.28 m/s, then on to a stop.
    y = CubicHermiteSpline([0.0, 2.2, CLOSEST, 4.2, 6.0], [0.0, 0.0, 0.17, 0.38, 0.38],
                           [0.0, 0.0, 0.28, 0.0, 0.0])(t)
    # Both hands close in symmetrically; after CLOSEST the receiver stays, the giver withdraws.
    receiver_x = 0.9 - 0.5 * (0.9 - np.where(t <= CLOSEST, d, D_MIN))
    giver = np.column_stack([receiver_x - d, y, np.full_like(t, 1.0)])
    receiver = np.column_stack([receiver_x, y, np.full_like(t, 1.0)])
    return Trajectory(t, giver, receiver)


@pytest.mark.parametrize("rate", [120.0, 30.0])
def test_a_carried_hold_is_not_released_before_the_hands_are_nearest(rate):
    # (Dated by the back-dating and the giver's lead alone: 3.29 s, 0.11 s early.)
    tr = _careful_pitcher(rate)
    transfers = [s for s in segment(tr, PhaseConfig()) if s.phase is Phase.TRANSFER]
    assert len(transfers) == 1
    assert CLOSEST - 0.02 <= transfers[0].end <= CLOSEST + 0.15
