from __future__ import annotations

import numpy as np
import pytest

from gazebot.core.minimum_jerk import minimum_jerk
from gazebot.core.phases.synthetic import SyntheticOptions, generate, synthetic_set


def test_min_jerk_profile_starts_and_ends_at_rest():
    s = np.linspace(0, 1, 1001)
    x = minimum_jerk(s)
    assert x[0] == 0 and x[-1] == pytest.approx(1)
    v = np.gradient(x, s)
    assert abs(v[0]) < 1e-3 and abs(v[-1]) < 1e-3
    assert v.max() == pytest.approx(1.875, rel=1e-3)  # peak speed of a minimum-jerk reach


def test_generation_is_reproducible_per_seed():
    a = generate(5, SyntheticOptions(dropouts_per_s=1.0, irregular=0.3))
    b = generate(5, SyntheticOptions(dropouts_per_s=1.0, irregular=0.3))
    np.testing.assert_array_equal(a.trajectory.giver_hand, b.trajectory.giver_hand)
    assert a.truth == b.truth


def test_truth_is_ordered_and_durations_plausible():
    for case in synthetic_set(20, seed=3):
        prev_end = -np.inf
        for h in case.truth:
            assert prev_end <= h.reach_start < h.transfer_start < h.transfer_end < h.retreat_end
            assert 0.4 <= h.transfer_start - h.reach_start <= 3.0
            assert 0.2 <= h.transfer_end - h.transfer_start <= 2.0
            prev_end = h.retreat_end


def test_hands_meet_at_transfer_and_part_after():
    case = generate(1, SyntheticOptions(noise=0.0, gripper_noise=0.0))
    tr, h = case.trajectory, case.truth[0]
    d = np.linalg.norm(tr.receiver_hand - tr.giver_hand, axis=1)
    during = (tr.t > h.transfer_start) & (tr.t < h.transfer_end)
    assert d[during].max() < 0.2
    assert d[during].max() - d[during].min() < 0.01  # both hold the object
    assert d[tr.t < h.reach_start].min() > d[during].max() + 0.2


@pytest.mark.parametrize("rate", [8.0, 240.0])
def test_sampling_rate_and_jitter(rate):
    tr = generate(0, SyntheticOptions(rate=rate, irregular=0.3)).trajectory
    dt = np.diff(tr.t)
    assert np.median(dt) == pytest.approx(1 / rate, rel=0.1)
    assert dt.min() > 0 and dt.std() > 0


def test_sitting_giver_is_lower_than_standing():
    sit = generate(0, SyntheticOptions(posture="sitting")).trajectory
    stand = generate(0, SyntheticOptions(posture="standing")).trajectory
    assert np.nanmean(sit.giver_face[:, 2]) < np.nanmean(stand.giver_face[:, 2]) - 0.1


def test_slow_giver_takes_longer():
    slow = [generate(s, SyntheticOptions(speed=0.6)).truth[0] for s in range(8)]
    fast = [generate(s, SyntheticOptions(speed=1.5)).truth[0] for s in range(8)]
    dur = [np.mean([h.retreat_end - h.reach_start for h in hs]) for hs in (slow, fast)]
    assert dur[0] > dur[1]


def test_robot_evidence_follows_the_transfer():
    case = generate(4, SyntheticOptions(robot_evidence=True))
    tr, h = case.trajectory, case.truth[0]
    closed_t = tr.t[tr.gripper_closed == 1]
    assert h.transfer_start < closed_t[0] < h.transfer_end
    share = tr.load_share
    assert share[tr.t < h.transfer_start].max() == 0
    assert tr.t[share > 0.9][0] >= h.transfer_end  # robot alone only after the release


def test_bad_options_are_rejected():
    with pytest.raises(ValueError):
        SyntheticOptions(rate=0.5)
    with pytest.raises(ValueError):
        SyntheticOptions(handovers=0)
