"""The online detector the engine runs: accuracy, latency and defined behavior on bad input."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from phase_truth import PHASE_KINDS, event_errors

from gazebot.core.phases import (
    OnlineDetector,
    PhaseConfig,
    Trajectory,
    run_online,
    segments_from_events,
)
from gazebot.core.phases.synthetic import SyntheticOptions, generate, synthetic_set
from gazebot.core.types import Event, EventKind, Phase, TrackingFrame


def _phase_events(events):
    return [e for e in events if e.kind in PHASE_KINDS]


def _frames(case):
    return case.trajectory.frames()


def test_each_handover_gives_reach_transfer_retreat_done_in_order(varied_set, online_results):
    for case, res in zip(varied_set, online_results, strict=True):
        kinds = [e.kind for e in _phase_events(res.events)]
        assert kinds == list(PHASE_KINDS) * len(case.truth), case.options
        handovers = [e.info["handover"] for e in _phase_events(res.events)]
        assert handovers == [k for k in range(len(case.truth)) for _ in range(4)]


def test_events_are_never_detected_before_they_happen(online_results):
    for res in online_results:
        for e in res.events:
            assert e.t <= e.detected_at
        phase_t = [e.t for e in _phase_events(res.events)]
        assert phase_t == sorted(phase_t)


@pytest.mark.parametrize("kind", [EventKind.TRANSFER_STARTED, EventKind.RETREAT_STARTED])
def test_transfer_events_are_accurate_from_motion_alone(varied_set, online_results, kind):
    err, lat = event_errors(varied_set, online_results, kind)
    # Measured: transfer start |err| median 18 / p90 75 / max 484 ms (a giver waiting for a
    # slowly arriving receiver at 15 Hz); release 32 / 105 / 144.
    assert np.median(err) <= 0.04
    assert np.percentile(err, 90) <= 0.12
    assert err.max() <= 0.5


def test_transfer_start_is_detected_within_250ms(varied_set, online_results):
    _, lat = event_errors(varied_set, online_results, EventKind.TRANSFER_STARTED)
    # Confirmed after min_transfer (80 ms) of hold: measured median 126 / p90 183 ms, 98 %.
    assert np.median(lat) <= 0.135
    assert np.mean(lat <= 0.25) >= 0.97


def test_reach_and_release_latency_from_motion_alone(varied_set, online_results):
    # A minimum-jerk motion needs time to show: 2 cm of closing, or 1 cm of separation (more
    # under heavy noise), seen past the smoothing's edge, before a reach or a release is
    # believed. Measured median / p90: reach 285 / 392 ms, release 264 / 376 ms.
    _, reach = event_errors(varied_set, online_results, EventKind.REACH_STARTED)
    _, release = event_errors(varied_set, online_results, EventKind.RETREAT_STARTED)
    assert np.median(reach) <= 0.29 and np.percentile(reach, 90) <= 0.4
    assert np.median(release) <= 0.27 and np.percentile(release, 90) <= 0.38


def test_robot_evidence_brings_all_transfer_events_within_250ms():
    cases = synthetic_set(20, seed=11, robot_evidence=True)
    results = [run_online(c.trajectory) for c in cases]
    err, lat = event_errors(cases, results, EventKind.RETREAT_STARTED)
    assert lat.max() <= 0.25
    assert np.percentile(err, 90) <= 0.12
    # With the robot's gripper state, the transfer starts when the gripper closes (both hold
    # the object), seen at the first sample after it closed.
    for case, res in zip(cases, results, strict=True):
        starts = [e for e in res.events if e.kind is EventKind.TRANSFER_STARTED]
        period = float(np.max(np.diff(case.trajectory.t)))
        for e, h in zip(starts, case.truth, strict=True):
            assert h.grasp <= e.t <= h.grasp + period + 1e-9
            assert e.detected_at - h.grasp <= 0.25
    sources = {e.info["source"] for r in results for e in r.events if e.kind in PHASE_KINDS}
    assert "load_share" in sources


def test_hands_resting_together_are_no_transfer_while_the_robot_has_not_grasped():
    # A giver holding the object out while the gripper, already close, has not closed yet.
    ts = np.arange(0.0, 4.0, 0.01)
    frames = []
    for t in ts:
        s = min(max((t - 0.5) / 1.0, 0.0), 1.0)
        hand = np.array([1.0, 0.0, 0.9]) + (10 * s**3 - 15 * s**4 + 6 * s**5) * np.array(
            [-0.4, 0.0, 0.1]
        )
        g = min(max((t - 0.6) / 1.2, 0.0), 1.0)
        grip = np.array([0.3, 0.0, 1.0]) + (10 * g**3 - 15 * g**4 + 6 * g**5) * np.array(
            [0.25, 0.0, 0.0]
        )
        frames.append(
            TrackingFrame.make(
                t, giver_hand=hand, receiver_hand=grip, gripper_closed=t >= 3.0, load_share=0.0
            )
        )
    det = OnlineDetector()
    events = [e for f in frames for e in det.update_all(f)]
    transfer = [e for e in events if e.kind is EventKind.TRANSFER_STARTED]
    assert len(transfer) == 1
    assert transfer[0].t == pytest.approx(3.0, abs=0.011)


def test_expected_phase_end_is_nan_when_idle_and_never_in_the_past():
    case = generate(2, SyntheticOptions(handovers=2))
    det = OnlineDetector()
    for f in _frames(case):
        det.update(f)
        if det.phase in (Phase.IDLE, Phase.DONE):
            assert math.isnan(det.expected_phase_end)
        else:
            assert det.expected_phase_end >= f.t
            assert det.phase_start <= f.t


def test_expected_reach_end_predicts_contact_halfway_through(varied_set):
    errs = []
    for case in varied_set[:25]:
        h = case.truth[0]
        half = h.reach_start + 0.5 * (h.transfer_start - h.reach_start)
        det = OnlineDetector()
        for f in _frames(case):
            det.update(f)
            if f.t >= half and det.phase is Phase.REACH:
                errs.append(det.expected_phase_end - h.transfer_start)
                break
    errs = np.abs(errs)
    assert len(errs) >= 20
    # Measured: median 0.11 s, p90 0.26 s, for reaches of 0.5-2.5 s (the late ones: reaches
    # confirmed after their halfway point, predicted from the typical duration). The speed
    # sag at the signals' one-sided edge is not read as a passed peak (it made the prediction
    # depend on when the analysis ran: p90 0.52-0.57 s).
    assert np.median(errs) <= 0.13 and np.percentile(errs, 90) <= 0.3


def test_several_events_in_one_sample_are_queued():
    det = OnlineDetector()
    base = dict(giver_hand=[1.0, 0, 0], receiver_hand=[0.85, 0, 0])
    assert det.update(TrackingFrame.make(0.0, **base, gripper_closed=False)) is None
    # The robot grasps although no reach was seen: reach_started and transfer_started at once.
    first = det.update(TrackingFrame.make(0.1, **base, gripper_closed=True))
    assert first.kind is EventKind.REACH_STARTED and det.pending == 1
    second = det.update(TrackingFrame.make(0.2, **base, gripper_closed=True))
    assert second.kind is EventKind.TRANSFER_STARTED and second.detected_at == 0.1
    assert det.pending == 0 and det.phase is Phase.TRANSFER
    assert det.update(TrackingFrame.make(0.3, **base, gripper_closed=True)) is None


def _with_gap(case, start, length):
    tr = case.trajectory
    gap = (tr.t >= start) & (tr.t < start + length)
    tr = tr.take(np.arange(len(tr)))
    tr.giver_hand[gap] = np.nan
    return tr


def test_short_gaps_are_held_without_tracking_events():
    case = generate(4, SyntheticOptions(rate=100))
    h = case.truth[0]
    clean = run_online(case.trajectory)
    gappy = run_online(_with_gap(case, 0.5 * (h.reach_start + h.transfer_start), 0.2))
    kinds = [e.kind for e in gappy.events]
    assert EventKind.TRACKING_LOST not in kinds
    assert kinds == [e.kind for e in clean.events]
    assert gappy.stats.held > 0


def test_long_gap_reports_tracking_lost_then_restored():
    case = generate(4, SyntheticOptions(rate=100))
    h = case.truth[0]
    t_gap = h.transfer_start + 0.1
    res = run_online(_with_gap(case, t_gap, 1.0))
    lost = [e for e in res.events if e.kind is EventKind.TRACKING_LOST]
    back = [e for e in res.events if e.kind is EventKind.TRACKING_RESTORED]
    assert len(lost) == 1 and len(back) == 1
    assert lost[0].t < t_gap <= lost[0].t + 0.02  # last valid sample
    assert lost[0].detected_at == pytest.approx(lost[0].t + 0.25, abs=0.02)
    assert lost[0].info["missing"] == ["giver_hand"]
    assert back[0].t == pytest.approx(t_gap + 1.0, abs=0.02)
    # The handover still completes after tracking returns.
    kinds = [e.kind for e in _phase_events(res.events)]
    assert kinds == list(PHASE_KINDS)


def test_duplicate_and_out_of_order_samples_are_ignored_and_counted():
    case = generate(6, SyntheticOptions(rate=60))
    frames = _frames(case)
    messy = []
    for i, f in enumerate(frames):
        messy.append(f)
        if i % 10 == 0:
            messy.append(f)  # duplicate
        if i % 17 == 0 and i > 3:
            messy.append(frames[i - 3])  # late sample
    bad = replace(frames[5], t=math.nan)
    messy.insert(6, bad)
    det_clean, det_messy = OnlineDetector(), OnlineDetector()
    clean = [e for f in frames for e in det_clean.update_all(f)]
    got = [e for f in messy for e in det_messy.update_all(f)]
    assert got == clean
    st = det_messy.stats
    assert st.duplicates == len(range(0, len(frames), 10))
    assert st.out_of_order == len([i for i in range(len(frames)) if i % 17 == 0 and i > 3])
    assert st.bad_time == 1
    assert st.samples == len(frames)


def test_jittered_sampling_gives_the_same_events_as_regular():
    regular = generate(8, SyntheticOptions(rate=120, irregular=0.0))
    jitter = generate(8, SyntheticOptions(rate=120, irregular=0.45))
    a = _phase_events(run_online(regular.trajectory).events)
    b = _phase_events(run_online(jitter.trajectory).events)
    assert [e.kind for e in a] == [e.kind for e in b]
    for ea, eb in zip(a, b, strict=True):
        assert abs(ea.t - eb.t) <= 0.06


def test_second_handover_starts_a_new_reach():
    case = generate(12, SyntheticOptions(handovers=2, rate=100))
    det = OnlineDetector()
    seen = []
    for f in _frames(case):
        for e in det.update_all(f):
            if e.kind in PHASE_KINDS:
                seen.append((e.kind, e.info["handover"], det.phase))
    assert [s[0] for s in seen] == list(PHASE_KINDS) * 2
    assert [s[1] for s in seen] == [0] * 4 + [1] * 4
    assert det.handover == 1 and det.phase is Phase.DONE


def test_resync_continues_from_the_adopted_phase():
    case = generate(4, SyntheticOptions(rate=100))
    h = case.truth[0]
    frames = _frames(case)
    det = OnlineDetector()
    known = Event(EventKind.TRANSFER_STARTED, h.transfer_start, h.transfer_start + 0.05)
    later = [f for f in frames if f.t > h.transfer_start + 0.1]
    # A restarted engine sees some frames, then learns the phase published before the restart.
    for f in later[:5]:
        det.update(f)
    det.resync(Event(EventKind.REACH_STARTED, h.reach_start, h.reach_start + 0.2))
    det.resync(known)
    assert det.phase is Phase.TRANSFER and det.phase_start == h.transfer_start
    events = [e for f in later[5:] for e in det.update_all(f)]
    kinds = [e.kind for e in _phase_events(events)]
    assert kinds == [EventKind.RETREAT_STARTED, EventKind.HANDOVER_DONE]
    assert abs(events[0].t - h.transfer_end) <= 0.2


def test_resync_follows_the_one_handover_state():
    det = OnlineDetector()
    det.resync(Event(EventKind.TRACKING_LOST, 1.0, 1.0))
    assert det.phase is Phase.IDLE
    det.resync(Event(EventKind.ROBOT_REACH_STARTED, 1.0, 1.0, {"planned_duration": 1.2}))
    # The robot's reach is the state's; the tracking has not shown the giver's yet (no end).
    assert det.phase is Phase.REACH and math.isnan(det.expected_phase_end)
    det.resync(Event(EventKind.ROBOT_GRASPED, 2.0, 2.0))
    assert det.phase is Phase.TRANSFER and det.phase_start == 2.0
    assert det.expected_phase_end >= 2.0


def test_resync_replay_counts_one_handover():
    det = OnlineDetector()
    for kind, t in [
        (EventKind.REACH_STARTED, 1.0),
        (EventKind.ROBOT_GRASPED, 2.1),
        (EventKind.TRANSFER_STARTED, 2.0),
    ]:
        det.resync(Event(kind, t, t))
    # The grasp started the transfer; the tracking's transfer start told after it is the
    # current phase's (ignored by the handover state's rules).
    assert det.handover == 0 and det.phase is Phase.TRANSFER and det.phase_start == 2.1
    det.resync(Event(EventKind.HANDOVER_DONE, 4.0, 4.0))
    det.resync(Event(EventKind.REACH_STARTED, 6.0, 6.0))
    assert det.handover == 1 and det.phase is Phase.REACH


def test_release_seen_through_load_share():
    det = OnlineDetector()
    p = dict(giver_hand=[1.0, 0, 0], receiver_hand=[0.9, 0, 0])
    det.resync(Event(EventKind.TRANSFER_STARTED, 0.0, 0.0))
    assert det.update(TrackingFrame.make(0.01, **p, load_share=0.5)) is None
    e = det.update(TrackingFrame.make(0.02, **p, load_share=0.95))
    assert e.kind is EventKind.RETREAT_STARTED and e.t == 0.02
    assert e.info["source"] == "load_share"


def test_segments_from_online_events_are_contiguous(varied_set, online_results):
    for case, res in zip(varied_set[:10], online_results[:10], strict=True):
        segs = segments_from_events(res.events, float(case.trajectory.t[-1]))
        assert len(segs) == 3 * len(case.truth)
        for k in range(0, len(segs), 3):
            assert segs[k].end == segs[k + 1].start and segs[k + 1].end == segs[k + 2].start
            assert all(s.detected_at is not None for s in segs[k : k + 3])


def test_config_is_used():
    strict = PhaseConfig(reach_onset_speed=5.0, rest_speed=0.05)
    res = run_online(generate(4, SyntheticOptions()).trajectory, strict)
    assert _phase_events(res.events) == []


def test_malformed_points_count_as_missing_and_numpy_flags_work():
    det = OnlineDetector()
    bad = TrackingFrame(0.0, giver_hand=[1.0, 0.0], receiver_hand=np.array([0.5, 0, 0]))
    assert det.update(bad) is None and det.stats.held == 1
    p = dict(giver_hand=[1.0, 0, 0], receiver_hand=[0.9, 0, 0])
    det.update(TrackingFrame.make(0.1, **p, gripper_closed=np.bool_(False)))
    e = det.update(TrackingFrame.make(0.2, **p, gripper_closed=np.bool_(True)))
    assert e is not None and e.kind is EventKind.REACH_STARTED and e.info["source"] == "gripper"


def test_retreat_adopted_by_resync_ends_when_the_hand_is_at_rest():
    # An engine restarted late in the retreat: the giver's hand is already back at rest.
    det = OnlineDetector()
    det.resync(Event(EventKind.RETREAT_STARTED, 1.0, 1.0))
    events = []
    for t in np.arange(1.5, 3.0, 0.01):
        frame = TrackingFrame.make(t, giver_hand=[1.0, -0.3, 0.85], receiver_hand=[0.4, 0, 1.0])
        events += det.update_all(frame)
    done = [e for e in events if e.kind is EventKind.HANDOVER_DONE]
    assert len(done) == 1 and done[0].info["source"] == "rest"
    assert done[0].detected_at < 2.5


def test_release_seen_only_after_a_restart_still_ends_the_handover_at_rest():
    # Restarted in the transfer; the first sample already says the robot holds the object
    # alone and the giver's hand is nearly back at rest.
    det = OnlineDetector()
    det.resync(Event(EventKind.TRANSFER_STARTED, 3.0, 3.0))
    events = []
    for t in np.arange(4.0, 6.0, 0.01):
        s = min((t - 4.0) / 0.3, 1.0)
        hand = np.array([0.97, -0.3, 0.86]) + s * np.array([0.03, 0.0, -0.01])
        frame = TrackingFrame.make(
            t, giver_hand=hand, receiver_hand=[0.4, 0, 1.0], gripper_closed=True, load_share=1.0
        )
        events += det.update_all(frame)
    kinds = [e.kind for e in events]
    assert kinds == [EventKind.RETREAT_STARTED, EventKind.HANDOVER_DONE]
    assert events[1].detected_at < 5.0


def test_resting_hands_skip_the_analysis_and_a_handover_runs_it():
    # The cheap trigger (engine.step cost): at rest almost every period skips the method;
    # a handover runs it around its boundaries and still gives every event.
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 10.0, 1 / 120)
    g = np.array([1.05, -0.2, 0.9]) + rng.normal(0.0, 0.002, (t.size, 3))
    r = np.array([0.35, -0.3, 0.25]) + rng.normal(0.0, 0.0003, (t.size, 3))
    rest = run_online(Trajectory(t, g, r))
    assert rest.stats.analyses <= 0.05 * (rest.stats.analyses + rest.stats.skipped)
    case = generate(3, SyntheticOptions(rate=120.0, posture="standing"))
    res = run_online(case.trajectory)
    assert [e.kind for e in _phase_events(res.events)] == list(PHASE_KINDS)
    assert 0 < res.stats.analyses <= 0.4 * (res.stats.analyses + res.stats.skipped)
