"""Issue 20's failing cases, generated with known phase times: joint carrying (the hands move
together ~1 s), long still holds (~1.3 s), quick light-cup handovers at 30 Hz or with 5 mm of
noise. Pins the generator's shape of each case and the detector's transfer on them."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.degrade import KINDS, degraded
from gazebot.core.phases import PhaseConfig, compute_signals, run_online, segment
from gazebot.core.phases.synthetic import CASE_KINDS, case_set
from gazebot.core.types import EventKind, Phase


@pytest.fixture(scope="module")
def cases():
    return {kind: case_set(kind, 12, seed=1) for kind in CASE_KINDS}


def _hold_stats(case):
    s = compute_signals(case.trajectory, PhaseConfig())
    h = case.truth[0]
    m = (s.t > h.transfer_start + 0.1) & (s.t < h.transfer_end - 0.05)
    common = np.linalg.norm(s.giver_v + s.receiver_v, axis=1)[m] / 2
    return s.distance[m], s.rel_speed[m], common


def test_carry_case_moves_together_with_small_relative_motion(cases):
    for case in cases["carry"]:
        h = case.truth[0]
        assert 0.85 <= h.transfer_end - h.transfer_start <= 1.25
        d, rel, common = _hold_stats(case)
        assert 0.25 <= d.mean() <= 0.5 and d.std() < 0.01  # hand frames ~0.35 m apart
        assert 0.1 <= np.median(common) <= 0.35  # the pair carries the object
        assert 0.015 <= np.median(rel) <= 0.10 and np.percentile(rel, 90) <= 0.12


def test_still_case_holds_steady_for_over_a_second(cases):
    for case in cases["still"]:
        h = case.truth[0]
        assert h.transfer_end - h.transfer_start >= 1.15
        _, rel, common = _hold_stats(case)
        assert np.percentile(rel, 90) < 0.03 and np.median(common) < 0.03


def test_quick_cases_are_short_at_their_rate_and_noise(cases):
    for kind, rate, noise in (("quick30", 30.0, 0.0015), ("quick_noisy", 120.0, 0.005)):
        for case in cases[kind]:
            h = case.truth[0]
            assert h.transfer_end - h.transfer_start <= 0.4
            assert np.median(np.diff(case.trajectory.t)) == pytest.approx(1 / rate, rel=0.15)
            assert case.options.noise == noise


def _transfer_errors(group):
    start, end = [], []
    for case in group:
        tr = [s for s in segment(case.trajectory, PhaseConfig()) if s.phase is Phase.TRANSFER]
        assert len(tr) == len(case.truth) == 1, case.options  # one transfer, never two
        start.append(tr[0].start - case.truth[0].transfer_start)
        end.append(tr[0].end - case.truth[0].transfer_end)
    return np.abs(start), np.abs(end)


@pytest.mark.parametrize(
    ("kind", "start_max", "end_med", "end_max"),
    [
        # Measured |start| med 51 / max 119 ms, |end| med 42 / max 184 ms (before the hold was
        # judged against the common motion: end med 77 / p90 303 / max 312 ms).
        ("carry", 0.15, 0.06, 0.22),
        # Measured start max 30, end med 16 / max 98 ms.
        ("still", 0.06, 0.03, 0.12),
        # Measured start max 77, end med 23 / max 58 ms.
        ("quick30", 0.10, 0.04, 0.08),
        # Measured start max 104, end med 25 / max 81 ms.
        ("quick_noisy", 0.13, 0.04, 0.10),
    ],
)
def test_each_case_gives_one_transfer_spanning_the_whole_hold(
    cases, kind, start_max, end_med, end_max
):
    start, end = _transfer_errors(cases[kind])
    assert start.max() <= start_max
    assert np.median(end) <= end_med and end.max() <= end_max


@pytest.mark.parametrize("kind", CASE_KINDS)
def test_online_reports_each_case_once_in_order(cases, kind):
    for case in cases[kind]:
        kinds = [
            e.kind
            for e in run_online(case.trajectory).events
            if e.kind not in (EventKind.TRACKING_LOST, EventKind.TRACKING_RESTORED)
        ]
        assert kinds == [
            EventKind.REACH_STARTED,
            EventKind.TRANSFER_STARTED,
            EventKind.RETREAT_STARTED,
            EventKind.HANDOVER_DONE,
        ], case.options


def _pass_on_the_move(rate=30.0, noise=0.0):
    """The giver's hand sweeps past the receiver's without stopping: the relative speed dips
    to 0.17 m/s (never under the seed's 0.15) at the closest point, t = 2 s."""
    t = np.arange(0.0, 4.0, 1.0 / rate)
    u = np.clip(t - 2.0, -1.2, 1.2)
    rel = np.stack([0.15 + 0.5 * u**2, 0.17 * u, np.zeros_like(u)], axis=1)
    rng = np.random.default_rng(0)
    receiver = np.tile([0.4, 0.0, 1.0], (t.size, 1)) + rng.normal(0, noise, (t.size, 3))
    giver = receiver - rel + rng.normal(0, noise, (t.size, 3))
    from gazebot.core.phases import Trajectory

    return Trajectory(t, giver, receiver)


@pytest.mark.parametrize("noise", [0.0, 0.002])
def test_a_pass_on_the_move_is_one_short_transfer_at_the_closest_slowest_point(noise):
    traj = _pass_on_the_move(noise=noise)
    assert segment(traj, PhaseConfig(method="seed-7.2.5")) == []  # never under 15 cm/s
    segs = segment(traj, PhaseConfig())
    assert [s.phase for s in segs] == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    assert segs[1].start <= 2.0 <= segs[1].end and segs[1].duration <= 0.3


def _walk_with_a_second_dip(rate=30.0):
    """A pair walking at 0.6 m/s: the hands meet and hold (1.5-1.9 s, 0.15 m apart), part to
    0.45 m, where their distance turns at once (its relative speed under 5 cm/s for a moment),
    close to 0.29 m sweeping across at 0.4 m/s and part (as in public on-the-move recordings:
    hyeonseong-kim98/dynamic_handover_dataset, motions normal_205, 863 and 883)."""
    t = np.arange(0.0, 5.0, 1.0 / rate)
    x = _ease(t, 0.3, 1.5, 0.9, 0.15)
    up = (t >= 1.9) & (t < 2.4)
    x = np.where(up, 0.30 - 0.15 * np.cos(np.pi * (t - 1.9) / 0.5), x)
    swing = (t >= 2.4) & (t < 3.4)
    x = np.where(swing, 0.35 + 0.1 * np.cos(np.pi * (t - 2.4) / 0.5), x)
    x = np.where(t >= 3.4, _ease(t, 3.4, 4.2, 0.45, 0.9), x)
    y = np.where(swing, 0.4 / np.pi * (1 - np.cos(np.pi * (t - 2.4))), 0.0)
    y = np.where(t >= 3.4, 0.8 / np.pi, y)
    receiver = np.stack([0.6 * t, np.zeros_like(t), np.ones_like(t)], axis=1)
    from gazebot.core.phases import Trajectory

    return Trajectory(t, receiver + np.stack([x, y, np.zeros_like(t)], axis=1), receiver)


def _ease(t, t0, t1, x0, x1):
    u = np.clip((t - t0) / (t1 - t0), 0.0, 1.0)
    return x0 + (x1 - x0) * (10 * u**3 - 15 * u**4 + 6 * u**5)


def test_where_the_distance_turns_at_the_top_of_a_dip_is_no_pass():
    # The second dip's slowest point is its top, where the hands' distance turns: the seed's
    # distance margin (0.2 m) reaches up there, and the walking giver's hand is never under
    # the onset speed, so it made a second handover with a 0.08 s reach. A pass is where the
    # hands have closed in (half min_approach below the dip's top); there they sweep across.
    segs = segment(_walk_with_a_second_dip(), PhaseConfig())
    assert [s.phase for s in segs] == [Phase.REACH, Phase.TRANSFER, Phase.RETREAT]
    assert 1.4 <= segs[1].start <= 1.6 and 1.7 <= segs[1].end <= 2.0


def test_a_sweep_that_stays_fast_is_no_transfer():
    # The same sweep at 0.3 m/s across: too fast to hand anything over.
    t = np.arange(0.0, 4.0, 1.0 / 30.0)
    u = np.clip(t - 2.0, -1.2, 1.2)
    rel = np.stack([0.15 + 0.5 * u**2, 0.3 * u, np.zeros_like(u)], axis=1)
    receiver = np.tile([0.4, 0.0, 1.0], (t.size, 1))
    from gazebot.core.phases import Trajectory

    traj = Trajectory(t, receiver - rel, receiver)
    assert [s for s in segment(traj, PhaseConfig()) if s.phase is Phase.TRANSFER] == []


@pytest.mark.parametrize("kind", CASE_KINDS)
def test_degraded_copies_keep_one_transfer_offline_and_online(cases, kind):
    # Measured: 128 of 128 copies (8 recordings per kind) within 0.3 s offline and online
    # within 0.35 s of the offline start.
    for i, case in enumerate(cases[kind][:2]):
        h = case.truth[0]
        for how in KINDS:
            traj = degraded(case.trajectory, how, np.random.default_rng(i))
            tr = [s for s in segment(traj, PhaseConfig()) if s.phase is Phase.TRANSFER]
            assert len(tr) == 1, (kind, i, how)
            assert abs(tr[0].start - h.transfer_start) <= 0.3, (kind, i, how)
            assert abs(tr[0].end - h.transfer_end) <= 0.3, (kind, i, how)
            ev = [e for e in run_online(traj).events if e.kind is EventKind.TRANSFER_STARTED]
            assert len(ev) == 1 and abs(ev[0].t - tr[0].start) <= 0.35, (kind, i, how)


def test_a_retreat_starting_slowly_under_noise_is_not_the_hold():
    # A still hold at 30 Hz with 5 mm of marker noise: the retreat starts slowly inside the
    # seed-rule core, and its relative speed dips under the hold's still bar by chance 0.26 s
    # after the release, 1.3 cm out of the held distance. The release, not before the last
    # still sample, was dated 0.26 s late; a still sample out of the hold's distance band
    # (from its median absolute deviation) is no longer the hold.
    from gazebot.core.phases.synthetic import SyntheticOptions, generate

    opts = SyntheticOptions(rate=30.0, noise=0.0015, handovers=3, marker_offset=0.3, hold="still")
    case = generate(105, opts)
    noisy = degraded(case.trajectory, "noise", np.random.default_rng(0))
    ends = [s.end for s in segment(noisy, PhaseConfig()) if s.phase is Phase.TRANSFER]
    assert len(ends) == 3 and abs(ends[2] - case.truth[2].transfer_end) <= 0.1


def test_an_early_lift_then_a_wait_is_not_the_reach_online():
    # Issue 20: a giver who lifted the cup early, then waited: the reach that leads into the
    # transfer must be the final approach, confirmed no earlier than 1 s before and no later
    # than 0.15 s after the hands have closed 20 % of the gap (the held-out bar: 7 of 8). The
    # lift ends as a stalled reach once the hand, having rested reach_stall (1 s), sets off
    # again toward the receiver.
    from gazebot.core.phases.synthetic import early_lift_set

    lags = []
    for case in early_lift_set(12, seed=4):
        h, tr = case.truth[0], case.trajectory
        d = np.linalg.norm(tr.receiver_hand - tr.giver_hand, axis=1)
        i0, i1 = np.searchsorted(tr.t, [h.reach_start, h.transfer_start])
        fifth = tr.t[i0 + np.flatnonzero(d[i0:i1] <= d[i0] - 0.2 * (d[i0] - d[i1]))[0]]
        events = [
            e
            for e in run_online(tr).events
            if e.kind not in (EventKind.TRACKING_LOST, EventKind.TRACKING_RESTORED)
        ]
        assert [e.kind for e in events[-4:]] == [
            EventKind.REACH_STARTED,
            EventKind.TRANSFER_STARTED,
            EventKind.RETREAT_STARTED,
            EventKind.HANDOVER_DONE,
        ], case.options
        earlier = [e for e in events[:-4] if e.kind is EventKind.HANDOVER_DONE]
        assert all(e.info["source"] == "stalled" for e in earlier)
        reach = events[-4]
        # Dated at the final approach's onset, not before the stall (1 s of rest after the
        # lift: after a short wait the approach may begin before the stall is seen).
        assert abs(reach.t - h.reach_start) <= 0.45
        lags.append(reach.detected_at - fifth)
    lags = np.array(lags)
    # Measured -0.21 .. +0.20 s, 11 of 12 within the window.
    assert np.count_nonzero((lags >= -1.0) & (lags <= 0.15)) >= 11 and lags.max() <= 0.25


def test_a_giver_holding_the_object_out_for_a_slow_robot_keeps_the_reach():
    # The robot sets off 2.5 s late: the giver's hand waits at the handover place (it closed
    # most of the gap) while nobody moves: the same reach goes on, no stall.
    from gazebot.core.phases.synthetic import SyntheticOptions, generate

    for seed in range(4):
        opts = SyntheticOptions(rate=120.0, noise=0.0015, marker_offset=0.3, robot_delay=2.5)
        kinds = [e.kind for e in run_online(generate(seed, opts).trajectory).events]
        assert kinds == [
            EventKind.REACH_STARTED,
            EventKind.TRANSFER_STARTED,
            EventKind.RETREAT_STARTED,
            EventKind.HANDOVER_DONE,
        ], seed
