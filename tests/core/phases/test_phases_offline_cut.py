"""Offline segmentation of recordings that end mid-handover, and the retreat's far-apart end."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.core.phases import PhaseConfig, compute_signals, segment
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.core.types import Phase


def _cut(tr, t_cut):
    return tr.take(np.flatnonzero(tr.t <= t_cut))


def _phases(segs):
    return [s.phase for s in segs]


def test_recording_cut_mid_transfer_runs_the_transfer_to_the_end():
    # The reviewer's case: cut at 2.98 s, true release 3.26 s. The release used to be invented
    # by back-dating from the data end (transfer 2.258-2.960, retreat 2.960-2.980).
    case = generate(3, SyntheticOptions(rate=100))
    h = case.truth[0]
    assert h.transfer_end > 3.2
    cut = _cut(case.trajectory, 2.98)
    segs = segment(cut)
    assert _phases(segs) == [Phase.REACH, Phase.TRANSFER]
    assert segs[1].end == float(cut.t[-1])
    assert abs(segs[1].start - h.transfer_start) <= 0.05
    assert segs[0].end == segs[1].start


@pytest.mark.parametrize(("seed", "rate"), [(3, 100.0), (5, 60.0), (7, 30.0), (9, 8.0)])
@pytest.mark.parametrize("where", [0.5, 0.95])
def test_cut_anywhere_in_the_transfer_gives_no_retreat(seed, rate, where):
    case = generate(seed, SyntheticOptions(rate=rate))
    h = case.truth[0]
    cut = _cut(case.trajectory, h.transfer_start + where * (h.transfer_end - h.transfer_start))
    segs = segment(cut)
    assert _phases(segs) == [Phase.REACH, Phase.TRANSFER]
    assert segs[1].end == float(cut.t[-1])


@pytest.mark.parametrize(("seed", "rate"), [(3, 100.0), (5, 60.0), (7, 30.0), (9, 8.0)])
def test_recording_cut_mid_reach_gives_a_reach_to_the_end(seed, rate):
    case = generate(seed, SyntheticOptions(rate=rate))
    h = case.truth[0]
    cut = _cut(case.trajectory, 0.5 * (h.reach_start + h.transfer_start))
    segs = segment(cut)
    assert _phases(segs) == [Phase.REACH]
    assert segs[0].end == float(cut.t[-1])
    assert abs(segs[0].start - h.reach_start) <= 0.1


@pytest.mark.parametrize(("seed", "rate"), [(3, 100.0), (5, 60.0), (7, 30.0), (9, 8.0)])
def test_recording_cut_mid_retreat_ends_the_retreat_at_the_end(seed, rate):
    case = generate(seed, SyntheticOptions(rate=rate))
    h = case.truth[0]
    cut = _cut(case.trajectory, 0.5 * (h.transfer_end + h.retreat_end))
    segs = segment(cut)
    assert _phases(segs) == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    assert segs[2].end == float(cut.t[-1])
    assert abs(segs[1].end - h.transfer_end) <= 0.13


def test_cut_in_the_second_reach_keeps_the_first_handover_and_a_trailing_reach():
    case = generate(3, SyntheticOptions(rate=60, handovers=2))
    h0, h1 = case.truth
    cut = _cut(case.trajectory, 0.5 * (h1.reach_start + h1.transfer_start))
    segs = segment(cut)
    assert _phases(segs) == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT, Phase.REACH]
    assert segs[3].handover == 1
    assert segs[2].end <= segs[3].start
    assert abs(segs[3].start - h1.reach_start) <= 0.1
    assert segs[3].end == float(cut.t[-1])


def test_cut_just_before_the_reach_shows_no_phase():
    case = generate(3, SyntheticOptions(rate=100))
    assert segment(_cut(case.trajectory, case.truth[0].reach_start + 0.02)) == []


def test_tracking_lost_for_good_mid_transfer_runs_the_transfer_to_the_end():
    case = generate(5, SyntheticOptions(rate=60))
    h, tr = case.truth[0], case.trajectory
    lost = tr.t > 0.5 * (h.transfer_start + h.transfer_end)
    tr.receiver_hand[lost] = np.nan
    tr.giver_hand[lost] = np.nan
    segs = segment(tr)
    assert _phases(segs) == [Phase.REACH, Phase.TRANSFER]
    assert segs[1].end == float(tr.t[-1])


def test_receiver_lost_for_good_mid_transfer_dates_the_release_by_the_giver():
    case = generate(5, SyntheticOptions(rate=60))
    h, tr = case.truth[0], case.trajectory
    tr.receiver_hand[tr.t > 0.5 * (h.transfer_start + h.transfer_end)] = np.nan
    segs = segment(tr)
    assert _phases(segs) == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    assert abs(segs[1].end - h.transfer_end) <= 0.15


def _far_time(s, t_release, far):
    """First grid time after ``t_release`` the smoothed giver hand is ``far`` from it."""
    i = int(np.searchsorted(s.t, t_release))
    moved = np.linalg.norm(s.giver[i:] - s.giver[i], axis=1)
    return float(s.t[i + int(np.flatnonzero(moved >= far)[0])])


@pytest.mark.parametrize("seed", [1, 3, 5])
def test_retreat_ends_when_the_giver_is_retreat_far_distance_away(seed):
    case = generate(seed, SyntheticOptions(rate=100))
    h = case.truth[0]
    near = PhaseConfig(retreat_far_distance=0.12)
    segs = segment(case.trajectory, near)
    retreat = segs[2]
    t_far = _far_time(compute_signals(case.trajectory.cleaned()[0], near), retreat.start, 0.12)
    assert retreat.end == pytest.approx(t_far, abs=0.011)
    assert retreat.end < h.retreat_end - 0.2  # well before the hand is back at rest
    # Otherwise identical: only the retreat's end moved.
    assert segs[:2] == segment(case.trajectory)[:2]


def test_retreat_ends_at_rest_when_the_hand_never_gets_far():
    case = generate(3, SyntheticOptions(rate=100))
    default = segment(case.trajectory)
    never = segment(case.trajectory, PhaseConfig(retreat_far_distance=5.0))
    assert default == never
    assert abs(default[2].end - case.truth[0].retreat_end) <= 0.1
