"""The receiver moves first (a robot-initiated handover, seed 6.3): the reach is still dated at
the giver's onset, never at the start of the analysed window."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.core.minimum_jerk import minimum_jerk as mj
from gazebot.core.phases import PhaseConfig, run_online, segment
from gazebot.core.phases.filtering import compute_signals
from gazebot.core.phases.rules.reach import reach_start
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.core.phases.trajectory import Trajectory
from gazebot.core.types import EventKind, Phase


def _moves(t: np.ndarray, t0: float, dur: float, a, b) -> np.ndarray:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a + mj((t - t0) / dur)[:, None] * (b - a)


def _index(s, t: float) -> int:
    return int(np.searchsorted(s.t, t))


def test_reach_starts_at_the_giver_onset_after_the_receiver_closed_the_gap():
    t = np.arange(0.0, 4.0, 1 / 120)
    giver = _moves(t, 1.5, 1.0, [1.0, 0.0, 1.0], [0.75, 0.0, 1.1])
    receiver = _moves(t, 0.5, 1.5, [0.2, 0.0, 1.0], [0.6, 0.0, 1.1])  # most of the gap
    s = compute_signals(Trajectory(t, giver, receiver), PhaseConfig())
    start = reach_start(s, PhaseConfig(), 0, _index(s, 2.6))
    assert start == pytest.approx(1.5, abs=0.08)


def test_a_giver_that_never_moves_dates_the_reach_at_the_receiver_onset():
    t = np.arange(0.0, 4.0, 1 / 120)
    giver = np.repeat([[0.8, 0.0, 1.1]], t.shape[0], axis=0)
    receiver = _moves(t, 2.0, 1.0, [0.2, 0.0, 1.0], [0.6, 0.0, 1.1])
    s = compute_signals(Trajectory(t, giver, receiver), PhaseConfig())
    start = reach_start(s, PhaseConfig(), 0, _index(s, 3.2))
    assert start == pytest.approx(2.0, abs=0.08)  # was the window's start (0 s)


def test_with_no_motion_at_all_the_reach_starts_where_it_was_asked_about():
    t = np.arange(0.0, 2.0, 1 / 60)
    still = np.repeat([[0.8, 0.0, 1.1]], t.shape[0], axis=0)
    s = compute_signals(Trajectory(t, still, still - [0.4, 0.0, 0.0]), PhaseConfig())
    hi = _index(s, 1.5)
    assert reach_start(s, PhaseConfig(), 0, hi) == pytest.approx(float(s.t[hi]))


@pytest.mark.parametrize("lead", [0.3, 1.0])
@pytest.mark.parametrize("rate", [30.0, 120.0])
def test_robot_initiated_handover_reach_dated_at_the_giver_onset(lead, rate):
    for seed in range(2):
        case = generate(seed, SyntheticOptions(rate=rate, robot_lead=lead, noise=0.002))
        truth = case.truth[0]
        segs = segment(case.trajectory, PhaseConfig())
        reach = [sg for sg in segs if sg.phase is Phase.REACH]
        # Measured: offline -0.09..+0.02 s, online -0.15..-0.01 s (8 seeds, 0.3-1.5 s leads).
        assert abs(reach[0].start - truth.reach_start) <= 0.12
        events = run_online(case.trajectory, PhaseConfig()).events
        first = next(e for e in events if e.kind is EventKind.REACH_STARTED)
        assert -0.2 <= first.t - truth.reach_start <= 0.1
        # The robot set off `lead` earlier: the reach is the giver's, not the robot's.
        assert first.t > truth.reach_start - 0.5 * lead
