"""``rules.release.giver_departure``: where a giver-led parting began, the giver's last speed
minimum before it, and why some minima are no departure."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.core.phases import PhaseConfig
from gazebot.core.phases.filtering import compute_signals
from gazebot.core.phases.rules.release import giver_departure
from gazebot.core.phases.trajectory import Trajectory

SLOWEST = 3.0  # s, the giver's speed bottoms out here


def _signals():
    """The giver's hand slows from 0.3 m/s to 0.05 m/s at ``SLOWEST`` (the approach ending),
    then speeds up to 0.25 m/s by 3.6 s and keeps it (carrying the object on); the receiver's
    hand rests 0.3 m ahead of where the giver's stops."""
    t = np.arange(0.0, 5.0, 1.0 / 120.0)
    v = np.interp(t, [0.0, 2.0, SLOWEST, 3.6, 5.0], [0.3, 0.3, 0.05, 0.25, 0.25])
    x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    giver = np.column_stack([x, np.zeros_like(t), np.ones_like(t)])
    receiver = np.column_stack([np.full_like(t, x[-1] + 0.3), np.zeros_like(t), np.ones_like(t)])
    return compute_signals(Trajectory(t, giver, receiver), PhaseConfig())


def _at(s, t: float) -> int:
    return int(np.searchsorted(s.t, t))


def test_the_departure_is_the_giver_s_last_speed_minimum_before_the_parting():
    s = _signals()
    got = giver_departure(s, _at(s, 3.8), t_min=2.5, tol=0.005)
    assert got == pytest.approx(SLOWEST, abs=0.03)


def test_a_speed_still_falling_at_the_earliest_time_looked_at_is_no_departure():
    s = _signals()
    assert giver_departure(s, _at(s, 3.8), t_min=3.2, tol=0.005) is None


def test_a_minimum_while_the_hands_still_closed_in_is_no_departure():
    # The hands were nearest after the giver's slowest: its speed rose with the pair's carry,
    # not as it let go (a careful reverse handover of a full pitcher, whose giver's slowest
    # came 0.3 s before the closest point: released there, 0.21 s before the seed rule's end
    # and a sample before the recorded closest point).
    s = _signals()
    assert giver_departure(s, _at(s, 3.8), 2.5, 0.005, t_met=SLOWEST - 0.2) is not None
    assert giver_departure(s, _at(s, 3.8), 2.5, 0.005, t_met=SLOWEST + 0.2) is None
