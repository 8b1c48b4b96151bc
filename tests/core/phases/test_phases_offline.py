"""Offline segmentation against synthetic handovers with known phase times."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.core.phases import PhaseConfig, Trajectory, segment
from gazebot.core.phases.synthetic import SyntheticOptions, generate, synthetic_set
from gazebot.core.types import Phase


def _errors(cases, results, field_seg, field_truth, phase):
    out = []
    for case, segs in zip(cases, results, strict=True):
        mine = [s for s in segs if s.phase is phase]
        for s, h in zip(mine, case.truth, strict=True):
            out.append(getattr(s, field_seg) - getattr(h, field_truth))
    return np.abs(np.array(out))


def test_every_handover_is_found_once(varied_set, offline_results):
    for case, segs in zip(varied_set, offline_results, strict=True):
        assert len(segs) == 3 * len(case.truth), case.options
    assert any(len(c.truth) == 2 for c in varied_set), "the set should hold double handovers"


def test_segments_are_contiguous_ordered_and_non_overlapping(offline_results):
    for segs in offline_results:
        for k in range(0, len(segs), 3):
            r, tr, rt = segs[k : k + 3]
            assert (r.phase, tr.phase, rt.phase) == (Phase.REACH, Phase.TRANSFER, Phase.RETREAT)
            assert r.handover == tr.handover == rt.handover == k // 3
            assert r.start <= r.end == tr.start < tr.end == rt.start <= rt.end
        for a, b in zip(segs, segs[1:], strict=False):
            assert a.end <= b.start + 1e-9


@pytest.mark.parametrize(
    ("seg_field", "truth_field"), [("start", "transfer_start"), ("end", "transfer_end")]
)
def test_transfer_boundaries_within_100ms_of_truth(
    varied_set, offline_results, seg_field, truth_field
):
    e = _errors(varied_set, offline_results, seg_field, truth_field, Phase.TRANSFER)
    # Measured on this set: start median 21 / p90 54 / max 122 ms (96 % within 100 ms),
    # end 30 / 94 / 129 ms (90 %). The truth is the kinematic stop of a minimum-jerk approach
    # and the giver's release before its hand moves (0-50 ms later).
    assert np.median(e) <= 0.04
    assert np.percentile(e, 90) <= 0.10
    assert np.mean(e <= 0.10) >= 0.85
    assert e.max() <= 0.20


def test_reach_start_and_retreat_end_near_truth(varied_set, offline_results):
    reach = _errors(varied_set, offline_results, "start", "reach_start", Phase.REACH)
    retreat = _errors(varied_set, offline_results, "end", "retreat_end", Phase.RETREAT)
    assert np.median(reach) <= 0.05 and np.percentile(reach, 80) <= 0.1
    # Measured reach start: median 43, p90 95 ms, max 162 ms, 92 % within 100 ms (an onset
    # hidden in a tracking gap is dated across the gap from the last seen rest).
    assert np.percentile(reach, 90) <= 0.10 and reach.max() <= 0.2
    assert np.mean(reach <= 0.1) >= 0.9
    assert np.median(retreat) <= 0.05 and np.percentile(retreat, 90) <= 0.1


def test_every_handover_of_three_more_seeds_is_found_once(seeds_set, seeds_offline_results):
    for case, segs in zip(seeds_set, seeds_offline_results, strict=True):
        assert len(segs) == 3 * len(case.truth), case.options


@pytest.mark.parametrize(
    ("phase", "seg_field", "truth_field", "median", "p90", "worst", "share"),
    [
        # Measured on seeds 1-3 (144 handovers), in ms: median / p90 / max, share within 100 ms.
        # Bounds: the 100 ms at p90, half of it at the median.
        (Phase.TRANSFER, "start", "transfer_start", 0.05, 0.10, 0.20, 0.9),  # 21/64/128, 95.1%
        (Phase.TRANSFER, "end", "transfer_end", 0.05, 0.10, 0.25, 0.9),  # 35/92/208, 92.4%
        (Phase.REACH, "start", "reach_start", 0.05, 0.10, 0.20, 0.9),  # 42/79/192, 97.9%
        (Phase.RETREAT, "end", "retreat_end", 0.05, 0.10, 0.50, 0.9),  # 34/80/441, 94.4%
    ],
)
def test_boundaries_near_truth_over_three_more_seeds(
    seeds_set, seeds_offline_results, phase, seg_field, truth_field, median, p90, worst, share
):
    e = _errors(seeds_set, seeds_offline_results, seg_field, truth_field, phase)
    assert e.size == 144
    assert np.median(e) <= median
    assert np.percentile(e, 90) <= p90
    assert e.max() <= worst
    assert np.mean(e <= 0.10) >= share


def _transfer(segs):
    (tr,) = [s for s in segs if s.phase is Phase.TRANSFER]
    return tr


@pytest.mark.parametrize("seed", range(8))
def test_approach_end_hidden_in_a_tracking_gap_is_not_dated_after_it(seed):
    # The hands settle inside a 0.35 s dropout. Dating the stop from the first settled sample
    # after the gap, then extrapolating by the gap-inflated interval, made starts 0.53 s late.
    case = generate(seed, SyntheticOptions(rate=100))
    h, tr = case.truth[0], case.trajectory
    tr.giver_hand[(tr.t > h.transfer_start - 0.1) & (tr.t < h.transfer_start + 0.25)] = np.nan
    err = _transfer(segment(tr)).start - h.transfer_start
    assert -0.15 <= err <= 0.1


def test_heavy_tracking_noise_at_low_rates_gives_no_late_starts():
    # 4 mm noise at 15-30 Hz lifts the hold's speed floor to the seed's 15 cm/s: the start is
    # where the speed sinks into that floor, early rather than late.
    errs = []
    for seed in range(20):
        for rate in (15.0, 30.0):
            case = generate(seed, SyntheticOptions(rate=rate, noise=0.004, speed=0.7))
            errs.append(_transfer(segment(case.trajectory)).start - case.truth[0].transfer_start)
    e = np.array(errs)
    assert e.max() <= 0.3  # measured 0.27 (two of 40 over 120 ms)
    assert np.count_nonzero(e > 0.12) <= 2
    assert np.median(np.abs(e)) <= 0.08  # measured 62 ms (slow givers, heavy noise)


def test_reach_onset_is_not_dated_after_a_dropout_inside_the_reach():
    # 100 Hz, 1 dropout/s: the reach's fastest part follows a dropout. The onset is the crossing
    # after the last slow sample *seen*, not the end of the dropout (was 0.24 s late).
    case = synthetic_set(12, seed=9)[11]
    (reach,) = [s for s in segment(case.trajectory) if s.phase is Phase.REACH]
    assert abs(reach.start - case.truth[0].reach_start) <= 0.05


def test_a_slow_retreat_dipping_under_the_onset_speed_is_not_over():
    # A slow giver (speed 0.7) with 2.4 mm noise: the retreat's speed wobbles under
    # reach_onset_speed just after starting; that dip ended the retreat 1.24 s early.
    case = synthetic_set(20, seed=5)[19]
    retreats = [s for s in segment(case.trajectory) if s.phase is Phase.RETREAT]
    assert len(retreats) == len(case.truth) == 2
    for seg, h in zip(retreats, case.truth, strict=True):
        assert abs(seg.end - h.retreat_end) <= 0.15


def test_default_beats_the_literal_seed_rule_at_the_transfer_start(varied_set, offline_results):
    # The seed's rule crosses 15 cm/s on the approach's tail, well before contact.
    cases = varied_set[:15]
    ours = _errors(cases, offline_results[:15], "start", "transfer_start", Phase.TRANSFER)
    seed_results = [segment(c.trajectory, PhaseConfig(method="seed-7.2.5")) for c in cases]
    lit = _errors(cases, seed_results, "start", "transfer_start", Phase.TRANSFER)
    assert np.median(ours) < np.median(lit)


def test_resting_hands_are_no_handover():
    rng = np.random.default_rng(0)
    t = np.arange(0, 5, 0.01)
    g = np.array([1.0, 0.0, 0.0]) + rng.normal(0, 0.002, (t.size, 3))
    r = np.array([0.4, -0.2, 0.2]) + rng.normal(0, 0.0003, (t.size, 3))
    assert segment(Trajectory(t, g, r)) == []


def test_receiver_coming_to_a_resting_giver_is_no_handover():
    # The robot returns home near a giver who never reaches: a distance dip, but no reach.
    t = np.arange(0, 4, 0.01)
    g = np.tile([0.9, 0.0, 0.0], (t.size, 1))
    s = np.clip((t - 1.0) / 1.2, 0, 1)
    mj = s**3 * (10 - 15 * s + 6 * s * s)
    r = np.array([0.2, -0.5, 0.3]) + mj[:, None] * (np.array([0.7, 0.0, 0.0]) - [0.2, -0.5, 0.3])
    assert segment(Trajectory(t, g, r)) == []


def test_sample_order_does_not_matter():
    case = generate(9, SyntheticOptions(rate=60))
    tr = case.trajectory
    perm = np.random.default_rng(1).permutation(len(tr))
    assert segment(tr.take(perm)) == segment(tr)


def test_dropout_inside_the_transfer_keeps_one_transfer():
    case = generate(3, SyntheticOptions(rate=100))
    h = case.truth[0]
    tr = case.trajectory
    mid = 0.5 * (h.transfer_start + h.transfer_end)
    gap = (tr.t > mid - 0.15) & (tr.t < mid + 0.15)
    tr.giver_hand[gap] = np.nan
    segs = segment(tr)
    transfers = [s for s in segs if s.phase is Phase.TRANSFER]
    assert len(transfers) == 1
    assert abs(transfers[0].start - h.transfer_start) <= 0.1
    assert abs(transfers[0].end - h.transfer_end) <= 0.1


def test_thresholds_come_from_the_config():
    case = generate(3, SyntheticOptions(rate=100))
    strict = PhaseConfig(transfer_speed_max=0.001, transfer_exit_speed=0.002, rest_speed=0.001)
    assert segment(case.trajectory, strict) == []
    assert len(segment(case.trajectory)) == 3


def test_too_short_recordings_give_nothing():
    assert segment(Trajectory(np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3)))) == []
    assert segment(Trajectory(np.array([0.0, 0.1]), np.zeros((2, 3)), np.ones((2, 3)))) == []


def test_reach_onset_hidden_in_a_tracking_gap_is_dated_across_it():
    case = generate(4, SyntheticOptions(rate=60))
    h = case.truth[0]
    tr = case.trajectory
    gap = (tr.t > h.reach_start - 0.1) & (tr.t < h.reach_start + 0.25)
    tr.giver_hand[gap] = np.nan
    reach = [s for s in segment(tr) if s.phase is Phase.REACH]
    assert len(reach) == 1
    assert abs(reach[0].start - h.reach_start) <= 0.15


def test_a_hold_the_last_release_rule_found_still_held_is_that_transfer(varied_set, monkeypatch):
    # On public on-the-move recordings (hyeonseong-kim98/dynamic_handover_dataset, motions
    # normal_453 and 541) the release rule found the hands still together past the start of
    # the next dip's core: that core made a second handover whose reach ran backwards (3.74 ->
    # 3.52 s). A core that starts before the last transfer's release is part of it.
    import gazebot.core.phases.methods.gazebot as method

    case = next(c for c in varied_set if len(c.truth) == 2)
    late = case.truth[1].transfer_start + 0.1
    real = method.transfer_end
    calls = []

    def held_on(s, c, core):
        calls.append(core)
        return (late, False) if len(calls) == 1 else real(s, c, core)

    monkeypatch.setattr(method, "transfer_end", held_on)
    segs = segment(case.trajectory, PhaseConfig())
    assert [s.phase for s in segs] == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    assert segs[1].end == pytest.approx(late) and all(s.start <= s.end for s in segs)
    assert len(calls) == 1  # the second core is not a handover
