"""``rules.transfer.speed_fell_for_good``: the approach's speed falls under the seed's 15 cm/s
for good at its last fall before it clearly slows (a Schmitt trigger), so an approach that
hovers at that speed is dated the same with and without noise."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gazebot.core.phases import PhaseConfig
from gazebot.core.phases.filtering import compute_signals
from gazebot.core.phases.rules.transfer import speed_fell_for_good
from gazebot.core.phases.trajectory import Trajectory

LEVEL, BAND = 0.15, 0.8


def _signals(speed, duration: float = 1.2):
    """Signals of still hands over ``duration`` s whose relative speed is ``speed(t)`` on the
    signals' own grid."""
    t = np.arange(0.0, duration, 1 / 120)
    hand = np.zeros((t.shape[0], 3))
    s = compute_signals(Trajectory(t, hand, hand + [0.4, 0.0, 0.0]), PhaseConfig())
    return dataclasses.replace(s, rel_speed=speed(s.t))


def _hover(dip: float | None = None, stop: tuple[float, float] | None = None):
    """0.4 m/s down to a hover at 15.3 cm/s from 0.3 s, a rise to 19 cm/s and the final fall
    through 15 cm/s at 0.7 s down to 5 cm/s; ``dip``: one sample at that speed at 0.35 s;
    ``stop``: 8 cm/s over that interval."""

    def speed(t):
        v = np.interp(t, [0.0, 0.3, 0.55, 0.6, 0.7, 0.9, 1.2],
                      [0.4, 0.153, 0.153, 0.19, LEVEL, 0.05, 0.05])
        if dip is not None:
            v[int(np.argmin(np.abs(t - 0.35)))] = dip
        if stop is not None:
            v[(t >= stop[0]) & (t < stop[1])] = 0.08
        return v

    return speed


def test_a_dip_in_a_hover_at_the_seed_speed_is_not_the_fall():
    clean, noisy = _signals(_hover()), _signals(_hover(dip=0.149))  # 30 Hz or 5 mm: a dip
    n = clean.t.shape[0]
    assert speed_fell_for_good(clean, 0, n, LEVEL, BAND) == pytest.approx(0.7, abs=0.01)
    assert speed_fell_for_good(noisy, 0, n, LEVEL, BAND) == pytest.approx(0.7, abs=0.01)


def test_a_push_after_the_speed_clearly_fell_does_not_move_it():
    s = _signals(_hover(stop=(0.32, 0.42)))  # under 0.8 x 15 cm/s: the approach had stopped
    got = speed_fell_for_good(s, 0, s.t.shape[0], LEVEL, BAND)
    assert got == pytest.approx(0.32, abs=0.02)


def test_a_speed_that_never_rises_again_falls_at_the_first_crossing():
    s = _signals(lambda t: np.interp(t, [0.0, 0.45, 1.0], [0.3, 0.0, 0.0]), duration=1.0)
    assert speed_fell_for_good(s, 0, s.t.shape[0], LEVEL, BAND) == pytest.approx(0.225, abs=0.005)
