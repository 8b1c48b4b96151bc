"""Phase detection on real motion capture (the KTH sample) and on generated recordings shaped
like it: marker-offset hand frames, noise, frozen samples, dropouts, 30-240 Hz."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.degrade import KINDS, degraded
from benchmarks.kth_data import RATE, force_truth, kth_dir
from gazebot.core.phases import PhaseConfig, run_online, segment
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.core.types import EventKind, Phase
from gazebot.io.recordings import PointNames, load_recording
from tests.core.phases.seed725_reference import qualifying_runs, seed_transfer

KTH = kth_dir()
needs_kth = pytest.mark.skipif(
    KTH is None, reason="KTH sample absent (fetch KTH-RPL/handovers_dataset, set GAZEBOT_KTH_DATA)"
)


def _kth():
    names = PointNames("giver_RHand", "taker_RHand", "giver_head")
    return load_recording(KTH, names, rate=RATE).trajectory  # type: ignore[arg-type]


def _phases(segs):
    return [s.phase for s in segs]


@needs_kth
def test_default_config_finds_the_kth_handover_within_100ms_of_the_force_truth():
    t0, t1 = force_truth(KTH)  # type: ignore[arg-type]
    segs = segment(_kth(), PhaseConfig())
    assert _phases(segs) == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    tr = segs[1]
    assert abs(tr.start - t0) <= 0.100 and abs(tr.end - t1) <= 0.100


@needs_kth
def test_default_beats_the_published_rule_at_the_kth_transfer_start():
    t0, t1 = force_truth(KTH)  # type: ignore[arg-type]
    ours = [s for s in segment(_kth(), PhaseConfig()) if s.phase is Phase.TRANSFER][0]
    seed = [
        s for s in segment(_kth(), PhaseConfig(method="seed-7.2.5")) if s.phase is Phase.TRANSFER
    ][0]
    assert abs(ours.start - t0) < abs(seed.start - t0)
    assert abs(ours.end - t1) <= max(abs(seed.end - t1), 0.05)


@needs_kth
@pytest.mark.parametrize("how", [*KINDS, "all"])
def test_degraded_kth_copies_keep_one_transfer_near_the_seed_rule(how):
    # The held-out bar: 40 of 40 degraded copies (here 8 per kind: 30 Hz, NaN bursts, 5 mm
    # noise, 6 cm marker offsets, and all at once) within 0.25 s of the seed rule's ends on
    # the clean recording, online within 0.35 s of the offline start. Measured 40 of 40
    # (starts +0.04 to +0.23 s, the clean recording's +0.15; ends -0.05 to +0.01 s; online
    # starts 0.01-0.28 s before the offline ones); 35 before a leading piece had to lie near
    # the later dips' closest distance (noise made one at the first sample, the hands 1.13 m
    # apart).
    clean = _kth()
    seed = segment(clean, PhaseConfig(method="seed-7.2.5"))
    s0, s1 = next((s.start, s.end) for s in seed if s.phase is Phase.TRANSFER)
    for i in range(8):
        copy = degraded(clean, how, np.random.default_rng(100 + i))
        tr = [s for s in segment(copy, PhaseConfig()) if s.phase is Phase.TRANSFER]
        assert len(tr) == 1, (how, i)
        assert abs(tr[0].start - s0) <= 0.25 and abs(tr[0].end - s1) <= 0.25, (how, i)
        ev = [e for e in run_online(copy).events if e.kind is EventKind.TRANSFER_STARTED]
        assert len(ev) == 1 and abs(ev[0].t - tr[0].start) <= 0.35, (how, i)


@needs_kth
def test_online_detects_the_kth_transfer_within_250ms_as_reach_transfer_retreat():
    t0, _ = force_truth(KTH)  # type: ignore[arg-type]
    res = run_online(_kth(), PhaseConfig())
    kinds = [e.kind for e in res.events]
    assert kinds == [
        EventKind.REACH_STARTED,
        EventKind.TRANSFER_STARTED,
        EventKind.RETREAT_STARTED,
        EventKind.HANDOVER_DONE,
    ]
    transfer = res.events[1]
    assert transfer.detected_at - t0 <= 0.250


def test_marker_offset_noisy_frozen_recordings_give_every_handover():
    errors = []
    for seed in range(6):
        rate = (30.0, 60.0, 120.0, 240.0, 45.0, 100.0)[seed]
        opts = SyntheticOptions(
            rate=rate,
            noise=0.0015,
            marker_offset=0.3 + 0.04 * seed,
            frozen_per_s=1.0,
            dropouts_per_s=0.5,
            irregular=0.2,
            handovers=1 + seed % 2,
        )
        sh = generate(100 + seed, opts)
        d = np.linalg.norm(sh.trajectory.receiver_hand - sh.trajectory.giver_hand, axis=1)
        assert np.nanmin(d) > 0.25  # hand frames never come close, as on real mocap
        segs = segment(sh.trajectory, PhaseConfig())
        assert _phases(segs) == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT] * len(sh.truth)
        for h, tr in zip(sh.truth, [s for s in segs if s.phase is Phase.TRANSFER], strict=True):
            errors += [tr.start - h.transfer_start, tr.end - h.transfer_end]
    # Truth here is the kinematic stop of a minimum-jerk approach: the rule (3 % of the peak
    # speed) lands a few tens of ms before it.
    assert float(np.median(np.abs(errors))) <= 0.06
    assert float(np.max(np.abs(errors))) <= 0.15


def test_frozen_samples_count_as_missing_not_as_a_stop():
    opts = SyntheticOptions(rate=120.0, noise=0.002, marker_offset=0.4)
    sh = generate(7, opts)
    traj = sh.trajectory
    h = sh.truth[0]
    # Freeze the giver's hand for 60 ms in mid-reach (the tracker repeats its last sample).
    mid = 0.5 * (h.reach_start + h.transfer_start)
    i = int(np.searchsorted(traj.t, mid))
    traj.giver_hand[i : i + 7] = traj.giver_hand[i - 1]
    segs = segment(traj, PhaseConfig())
    assert _phases(segs) == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    assert abs(segs[1].start - h.transfer_start) <= 0.100


# Choices the seed's sentence leaves open, stated for the reference (seed725_reference.py):
# relative speed over +-0.05 s (the implementation's seed_speed_half_window: the sentence names no
# filter, so both read the same window; the reference takes the nearest samples, the
# implementation interpolates), and the handover windows given by the generator's truth (the
# seed cut its recordings by hand; the implementation finds them itself).
HALF = 0.05


def _windows(sh):
    """Each handover's window: between the midpoints of the rests that separate them."""
    t = sh.trajectory.t
    cuts = [float(t[0])]
    for a, b in zip(sh.truth, sh.truth[1:], strict=False):
        cuts.append(0.5 * (a.retreat_end + b.reach_start))
    cuts.append(float(t[-1]))
    return list(zip(cuts, cuts[1:], strict=False))


@pytest.mark.parametrize("seed", range(8))
def test_seed_725_method_matches_the_sentence_read_independently(seed):
    opts = SyntheticOptions(
        rate=(30.0, 60.0, 120.0, 240.0)[seed % 4],
        noise=0.002,
        marker_offset=0.35 * (seed % 2),
        handovers=1 + seed % 3,
        dropouts_per_s=0.3 * (seed % 2),
    )
    sh = generate(300 + seed, opts)
    traj = sh.trajectory
    ours = [s for s in segment(traj, PhaseConfig(method="seed-7.2.5")) if s.phase is Phase.TRANSFER]
    assert len(ours) == len(sh.truth)  # it finds every handover by itself
    dt = 1.0 / opts.rate
    tol = 2 * dt + 1e-9  # nearest samples against interpolation: up to two samples apart
    seen = traj.t[np.isfinite(traj.giver_hand).all(1) & np.isfinite(traj.receiver_hand).all(1)]

    def by_a_gap(x):
        # A tracking gap (over two sample periods) within HALF of x: there the reference has
        # no speed (its nearest samples leave t +- HALF) where the implementation interpolates
        # across the gap, a choice the sentence does not make either way.
        i = np.searchsorted(seen, [x - HALF - dt, x + HALF + dt])
        return bool(np.any(np.diff(seen[max(i[0] - 1, 0) : i[1] + 1]) > 2.5 * dt))

    for window, s in zip(_windows(sh), ours, strict=True):
        args = (traj.t, traj.giver_hand, traj.receiver_hand, window, HALF)
        first, last = seed_transfer(*args)
        runs = qualifying_runs(*args)
        # The transfer lies within the sentence's widest reading (first to last qualifying
        # sample) ...
        assert first - tol <= s.start or by_a_gap(s.start)
        assert s.end <= last + tol or by_a_gap(s.end)
        # ... and is its longest run (the implementation's reading of "portion" when noise
        # splits it; a single run is the whole span).
        a, b = max(runs, key=lambda r: r[1] - r[0])
        assert abs(s.start - a) <= tol or by_a_gap(s.start) or by_a_gap(a)
        assert abs(s.end - b) <= tol or by_a_gap(s.end) or by_a_gap(b)


@needs_kth
def test_seed_725_method_matches_the_sentence_read_independently_on_kth():
    # The KTH sample holds one handover: its window is the whole recording.
    traj = _kth()
    window = (float(traj.t[0]), float(traj.t[-1]))
    args = (traj.t, traj.giver_hand, traj.receiver_hand, window, HALF)
    runs = qualifying_runs(*args)
    ours = [s for s in segment(traj, PhaseConfig(method="seed-7.2.5")) if s.phase is Phase.TRANSFER]
    assert len(ours) == 1
    a, b = max(runs, key=lambda r: r[1] - r[0])
    assert abs(ours[0].start - a) <= 2 / RATE and abs(ours[0].end - b) <= 2 / RATE


def test_seed_443_splits_one_giving_motion_with_the_published_fractions():
    sh = generate(5, SyntheticOptions(rate=100.0, noise=0.0005))
    segs = segment(sh.trajectory, PhaseConfig(method="seed-4.4.3"))
    assert _phases(segs) == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    traj = sh.trajectory
    dist = np.linalg.norm(traj.giver_hand - traj.giver_hand[0], axis=1)
    i = int(np.searchsorted(traj.t, segs[0].start))
    # The reach begins at the first sample farther than 0.41 d_max from the start.
    assert dist[i] > 0.41 * dist.max() and dist[i - 1] <= 0.41 * dist.max()


def test_no_handover_gives_no_segments_with_every_method():
    t = np.arange(0, 5, 0.01)
    g = np.tile([1.0, 0.0, 1.0], (t.size, 1)) + np.random.default_rng(0).normal(
        0, 0.001, (t.size, 3)
    )
    r = np.tile([0.3, 0.0, 1.0], (t.size, 1))
    from gazebot.core.phases import Trajectory

    traj = Trajectory(t, g, r)
    for m in ("gazebot", "seed-7.2.5", "seed-4.4.3"):
        assert segment(traj, PhaseConfig(method=m)) == [], m


def test_seed_443_as_published_splits_a_still_hand_into_phantom_phases():
    # Why seed_min_motion exists: the published fractions of the recording's own maxima split
    # 1 mm of marker noise on a still hand into reach, transfer and retreat.
    t = np.arange(0, 5, 0.01)
    g = np.tile([1.0, 0.0, 1.0], (t.size, 1)) + np.random.default_rng(0).normal(
        0, 0.001, (t.size, 3)
    )
    from gazebot.core.phases import Trajectory

    traj = Trajectory(t, g, np.tile([0.3, 0.0, 1.0], (t.size, 1)))
    published = PhaseConfig(method="seed-4.4.3", seed_min_motion=0.0)
    assert _phases(segment(traj, published)) == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    assert segment(traj, PhaseConfig(method="seed-4.4.3")) == []


@needs_kth
@pytest.mark.parametrize(
    "giver, taker", [("giver_RFArm", "taker_RFArm"), ("giver_RHand", "taker_RFArm")]
)
def test_kth_with_forearm_markers_still_gives_one_handover(giver, taker):
    # Another marker placement on the same recording: wrist-level frames, farther apart.
    t0, t1 = force_truth(KTH)  # type: ignore[arg-type]
    traj = load_recording(KTH, PointNames(giver, taker), rate=RATE).trajectory  # type: ignore[arg-type]
    segs = segment(traj, PhaseConfig())
    assert _phases(segs) == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    assert abs(segs[1].start - t0) <= 0.100 and abs(segs[1].end - t1) <= 0.100
    kinds = [e.kind for e in run_online(traj, PhaseConfig()).events]
    assert kinds == [
        EventKind.REACH_STARTED,
        EventKind.TRANSFER_STARTED,
        EventKind.RETREAT_STARTED,
        EventKind.HANDOVER_DONE,
    ]
