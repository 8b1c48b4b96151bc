"""Each built-in behavior's timing, as the seed defines it (6.3.2, 6.4.2, 6.4.3)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from behavior_helpers import FACE, ctx, ev, feed, hand_at

from gazebot.core.behaviors import BehaviorMachine, load_behavior
from gazebot.core.types import Phase

R, T, E, D = Phase.REACH, Phase.TRANSFER, Phase.RETREAT, Phase.DONE


def machine(name: str, seed: int = 0) -> BehaviorMachine:
    return BehaviorMachine(load_behavior(name), seed=seed)


def kind(m: BehaviorMachine, t: float, phase: Phase, start: float, end: float = math.nan) -> str:
    return m.target(ctx(t, phase, start, end)).kind


def run_standard(m: BehaviorMachine, robot: bool = True) -> dict[str, str]:
    """A handover: reach 1.0-2.0 s, transfer 2.0-2.5 s, retreat 2.5-3.5 s, done at 3.5 s.

    Returns the target kind at labelled instants; the detector's predicted ends are exact.
    """
    out = {"idle": kind(m, 0.5, Phase.IDLE, 0.0)}
    feed(m, ev("reach_started", 1.0))
    if robot:
        feed(m, ev("robot_reach_started", 1.0, planned_duration=1.0))
    for t in (1.0, 1.3, 1.49, 1.51, 1.99):
        out[f"reach@{t}"] = kind(m, t, R, 1.0, 2.0)
    if robot:
        feed(m, ev("robot_reach_ended", 2.0))
        feed(m, ev("robot_grasped", 2.05))
    feed(m, ev("transfer_started", 2.0))
    for t in (2.0, 2.2, 2.49):
        out[f"transfer@{t}"] = kind(m, t, T, 2.0, 2.5)
    feed(m, ev("retreat_started", 2.5))
    if robot:
        feed(m, ev("robot_retreat_started", 2.5, planned_duration=1.0))
    for t in (2.5, 2.8, 2.874, 2.876, 2.99, 3.01, 3.4):
        out[f"retreat@{t}"] = kind(m, t, E, 2.5, 3.5)
    feed(m, ev("handover_done", 3.5))
    out["done"] = kind(m, 3.6, D, 3.5)
    return out


def test_face_looks_at_the_face_before_during_and_after():
    assert set(run_standard(machine("face")).values()) == {"face"}


def test_hand_looks_at_the_hand_continuously_before_during_and_after_the_handover():
    # Seed 6.3.2: "Continuously look at the giver's hand" -- the whole video, not the face outside.
    assert set(run_standard(machine("hand")).values()) == {"hand"}


def test_short_face_hand_shifts_to_the_hand_when_the_reach_starts():
    m = machine("short-face-hand")
    assert kind(m, 0.9, Phase.IDLE, 0.0) == "face"
    feed(m, ev("reach_started", 1.0))
    assert kind(m, 1.0, R, 1.0) == "hand"
    got = run_standard(machine("short-face-hand"))
    assert got["idle"] == "face" and got["done"] == "face"
    assert all(v == "hand" for k, v in got.items() if k.startswith(("reach", "transfer")))


def test_long_face_hand_shifts_to_the_hand_when_the_robot_reach_ends():
    m = machine("long-face-hand")
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("robot_reach_started", 1.1, planned_duration=0.6))
    assert kind(m, 1.69, R, 1.0, 2.0) == "face"  # past the robot's planned end: still face
    feed(m, ev("robot_reach_ended", 1.8))
    assert kind(m, 1.79, R, 1.0, 2.0) == "face"
    assert kind(m, 1.8, R, 1.0, 2.0) == "hand"
    got = run_standard(machine("long-face-hand"))
    assert [got[f"reach@{t}"] for t in (1.0, 1.51, 1.99)] == ["face"] * 3
    assert got["transfer@2.0"] == "hand"


def test_long_face_hand_without_robot_events_keeps_the_face_until_the_retreat():
    # No robot_reach_ended: the face until the retreat, when the robot has surely arrived.
    got = run_standard(machine("long-face-hand"), robot=False)
    assert got["reach@1.99"] == "face" and got["transfer@2.49"] == "face"
    assert got["retreat@2.5"] == "hand"


def test_long_face_hand_waits_for_the_robot_even_when_the_transfer_is_seen_first():
    m = machine("long-face-hand")
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("transfer_started", 1.8))
    assert kind(m, 1.9, T, 1.8) == "face"
    feed(m, ev("robot_reach_ended", 1.95))
    assert kind(m, 1.95, T, 1.8) == "hand"


def test_face_hand_face_shifts_halfway_through_reach_and_retreat():
    got = run_standard(machine("face-hand-face"))
    assert [got[f"reach@{t}"] for t in (1.0, 1.3, 1.49, 1.51, 1.99)] == [
        "face",
        "face",
        "face",
        "hand",
        "hand",
    ]
    assert {got[f"transfer@{t}"] for t in (2.0, 2.2, 2.49)} == {"hand"}
    assert [got[f"retreat@{t}"] for t in (2.5, 2.8, 2.99, 3.01, 3.4)] == [
        "hand",
        "hand",
        "hand",
        "face",
        "face",
    ]
    assert got["done"] == "face"


def test_face_hand_face_halfway_falls_back_to_the_robot_planned_duration():
    m = machine("face-hand-face")
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("robot_reach_started", 1.2, planned_duration=1.8))  # robot arrives at 3.0 s
    assert kind(m, 1.99, R, 1.0) == "face"  # no detector prediction (NaN): halfway = 2.0 s
    assert kind(m, 2.0, R, 1.0) == "hand"


def test_face_hand_face_halfway_waits_for_the_later_of_giver_and_robot_arrival():
    # The reach ends when both hands have arrived: the giver at 1.6 s, the robot at 4.0 s.
    m = machine("face-hand-face")
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("robot_reach_started", 1.0, planned_duration=3.0))
    assert kind(m, 2.49, R, 1.0, 1.6) == "face"
    assert kind(m, 2.5, R, 1.0, 1.6) == "hand"  # halfway of the 1.0-4.0 s reach


def test_face_hand_face_uses_the_detector_prediction_when_the_robot_arrives_first():
    m = machine("face-hand-face")
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("robot_reach_started", 1.0, planned_duration=0.4))
    assert kind(m, 1.29, R, 1.0, 1.6) == "face"
    assert kind(m, 1.3, R, 1.0, 1.6) == "hand"  # halfway of the predicted 1.0-1.6 s reach


def test_face_hand_face_without_any_estimate_uses_the_human_mean_phase_length():
    spec = load_behavior("face-hand-face")
    m = BehaviorMachine(spec)
    feed(m, ev("reach_started", 0.0))
    half = 0.5 * spec.phase_durations_s.reach
    assert kind(m, half - 0.01, R, 0.0) == "face"
    assert kind(m, half + 0.01, R, 0.0) == "hand"


def test_face_hand_face_keeps_the_hand_when_the_estimate_grows_later():
    m = machine("face-hand-face")
    feed(m, ev("reach_started", 0.0))
    assert kind(m, 0.6, R, 0.0, 1.0) == "hand"
    assert kind(m, 0.7, R, 0.0, 3.0) == "hand"  # estimate revised to 3 s: no shift back


def test_face_hand_face_as_studied_is_face_in_reach_hand_in_transfer_face_in_retreat():
    # The phases as the seed's robot sensed them: the transfer from the end of its own reach
    # (2.0 s; not its grasp at 2.05 s), the retreat from its own retreat (2.5 s).
    got = run_standard(machine("face-hand-face-as-studied"))
    assert {got[f"reach@{t}"] for t in (1.0, 1.3, 1.51, 1.99)} == {"face"}
    assert {got[f"transfer@{t}"] for t in (2.0, 2.2, 2.49)} == {"hand"}
    assert {got[f"retreat@{t}"] for t in (2.5, 2.8, 3.01, 3.4)} == {"face"}


def test_face_hand_face_as_studied_holds_the_face_past_the_expected_reach_end():
    m = machine("face-hand-face-as-studied")
    feed(m, ev("reach_started", 0.0))
    assert kind(m, 5.0, R, 0.0, 1.0) == "face"


def test_hand_face_turns_to_the_face_shortly_after_the_retreat_starts():
    spec = load_behavior("hand-face")
    delay = spec.parameters["retreat_face"].delay
    assert 0.0 < delay <= 0.5  # "slightly after" (seed 6.4.2), fitted to the receivers
    got = run_standard(BehaviorMachine(spec))
    assert all(v == "hand" for k, v in got.items() if k.startswith(("reach", "transfer")))
    assert got["retreat@2.5"] == "hand" and got["retreat@2.874"] == "hand"
    assert got["retreat@2.876"] == "face" and got["retreat@3.4"] == "face"


def test_hand_face_as_studied_turns_to_the_face_once_the_robot_retreats():
    m = machine("hand-face-as-studied")
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("transfer_started", 2.0))
    assert kind(m, 2.1, T, 2.0) == "hand"
    feed(m, ev("robot_retreat_started", 2.2, planned_duration=1.0))  # retreats after grasping
    assert kind(m, 2.19, T, 2.0) == "hand"
    assert kind(m, 2.2, T, 2.0) == "face"
    feed(m, ev("retreat_started", 2.4))
    assert kind(m, 2.4, E, 2.4) == "face"
    got = run_standard(machine("hand-face-as-studied"))
    assert got["retreat@2.5"] == "face"


def test_hand_face_as_studied_keeps_the_hand_in_retreat_until_the_robot_retreats():
    m = machine("hand-face-as-studied")
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("retreat_started", 2.0))
    assert kind(m, 2.5, E, 2.0) == "hand"
    feed(m, ev("robot_retreat_started", 2.6))
    assert kind(m, 2.6, E, 2.0) == "face"


def test_as_studied_variants_are_parameters_of_the_same_behavior():
    for name in ("face-hand-face", "hand-face"):
        base, variant = load_behavior(name), load_behavior(f"{name}-as-studied")
        assert variant.extends == name
        assert variant.segments == base.segments
        assert variant.parameters != base.parameters


@pytest.mark.parametrize("name", ["hand", "face-hand-face", "hand-face", "short-face-hand"])
def test_the_returned_point_follows_the_moving_hand(name):
    m = machine(name)
    feed(m, ev("reach_started", 0.0))
    feed(m, ev("transfer_started", 1.0))
    for t in (1.1, 1.2, 1.3):
        target = m.target(ctx(t, T, 1.0))
        assert target.kind == "hand"
        np.testing.assert_allclose(target.point, hand_at(t))


def test_before_and_after_gaze_are_configurable(tmp_path):
    path = tmp_path / "shy.yaml"
    path.write_text(
        "before: rest\nafter: handover_location\n"
        "segments:\n  - {phase: reach, at: 0.0, target: hand}\n",
        encoding="utf-8",
    )
    m = BehaviorMachine(load_behavior(path))
    assert kind(m, 0.0, Phase.IDLE, 0.0) == "rest"
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("handover_done", 2.0))
    assert kind(m, 2.1, D, 2.0) == "handover_location"


def test_tracking_lost_holds_the_gaze_then_looks_at_the_last_face():
    m = machine("hand")
    feed(m, ev("reach_started", 0.0))
    before = m.target(ctx(0.5, R, 0.0))
    assert before.kind == "hand"
    feed(m, ev("tracking_lost", 0.5))
    nan = np.full(3, np.nan)
    held = m.target(ctx(0.7, R, 0.0, face=nan, hand=nan))
    assert held.kind == "hand"
    np.testing.assert_allclose(held.point, before.point)  # hold: the point does not move
    hold = load_behavior("hand").tracking_lost.hold_s
    later = m.target(ctx(0.5 + hold + 0.01, R, 0.0, face=nan, hand=nan))
    assert later.kind == "face"
    np.testing.assert_allclose(later.point, FACE)  # the last known face position
    assert m.state == "reach_hand_lost"
    feed(m, ev("tracking_restored", 1.5))
    assert m.target(ctx(1.6, R, 0.0)).kind == "hand"
    assert m.state == "reach_hand"


def test_human_receiver_is_reproducible_for_a_seed():
    def trace(seed: int) -> list[str]:
        m = machine("human-receiver", seed)
        out = []
        for k in range(20):
            t0 = 10.0 * k
            feed(m, ev("reach_started", t0))
            out += [kind(m, t0 + f, R, t0, t0 + 1.0) for f in (0.1, 0.5, 0.9)]
            feed(m, ev("transfer_started", t0 + 1.0))
            out += [kind(m, t0 + 1.0 + f, T, t0 + 1.0, t0 + 1.5) for f in (0.1, 0.4)]
            feed(m, ev("retreat_started", t0 + 1.5))
            out += [kind(m, t0 + 1.5 + f, E, t0 + 1.5, t0 + 2.5) for f in (0.1, 0.5, 0.9)]
            feed(m, ev("handover_done", t0 + 2.5))
        return out

    assert trace(7) == trace(7)
    assert trace(7) != trace(8)


def test_human_receiver_draws_patterns_with_the_fitted_probabilities():
    spec = load_behavior("human-receiver")
    m = BehaviorMachine(spec, seed=1)
    counts: dict[str, int] = {}
    n = 1000
    for k in range(n):
        feed(m, ev("reach_started", 10.0 * k))
        counts[m.pattern] = counts.get(m.pattern, 0) + 1
        feed(m, ev("handover_done", 10.0 * k + 2.0))
    for p in spec.human.patterns:
        assert abs(counts.get(p.name, 0) / n - p.probability) < 0.05, p.name


def test_human_receiver_shift_times_follow_the_fitted_distributions():
    model = load_behavior("human-receiver").human
    rng = np.random.default_rng(0)
    fractions: dict[tuple[str, str], list[float]] = {}
    for _ in range(3000):
        _, segments = model.sample(rng)
        for seg in segments:
            if seg.at.fraction > 0:
                fractions.setdefault((seg.phase, seg.target), []).append(seg.at.fraction)
    for shift in model.shifts:
        got = fractions[(shift.phase, shift.to_target)]
        assert abs(np.mean(got) - shift.fraction.mean) < 0.03, shift


def test_face_hand_face_retreat_halfway_follows_the_giver_not_the_slower_robot():
    # The giver is back at rest at 3.5 s (detector's prediction); the robot needs until 5.0 s.
    m = machine("face-hand-face")
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("transfer_started", 2.0))
    feed(m, ev("retreat_started", 2.5))
    feed(m, ev("robot_retreat_started", 2.6, planned_duration=2.4))
    assert kind(m, 2.99, E, 2.5, 3.5) == "hand"
    assert kind(m, 3.0, E, 2.5, 3.5) == "face"  # halfway of the giver's 2.5-3.5 s retreat


def test_the_robots_reach_starts_the_reach_before_the_detector_sees_the_giver():
    # Seed 6.3: the robot starts its reach and the giver responds; the detector still says idle
    # (first handover) or done (the next one) until the giver moves.
    m = machine("short-face-hand")
    assert kind(m, 0.5, Phase.IDLE, 0.0) == "face"
    feed(m, ev("robot_reach_started", 1.0, planned_duration=1.2))
    assert kind(m, 1.0, Phase.IDLE, 0.0) == "hand" and m.phase is R
    feed(m, ev("reach_started", 1.4))  # the giver's reach: the handover's reach began at 1.0
    assert kind(m, 1.5, R, 1.4) == "hand"
    for kind_, t in (("transfer_started", 2.3), ("retreat_started", 3.0), ("handover_done", 4.0)):
        feed(m, ev(kind_, t))
    assert kind(m, 5.0, D, 4.0) == "face"
    feed(m, ev("robot_reach_started", 10.0, planned_duration=1.2))
    assert kind(m, 10.01, D, 4.0) == "hand" and m.phase is R


def test_the_reach_start_is_the_earlier_of_the_robots_and_the_givers():
    m = machine("face-hand-face")
    feed(m, ev("robot_reach_started", 1.0, planned_duration=1.0))  # robot arrives at 2.0 s
    feed(m, ev("reach_started", 1.4))
    # Halfway through the 1.0-2.0 s reach (not 1.4-2.0 s): 1.5 s.
    assert kind(m, 1.49, R, 1.4, 1.9) == "face"
    assert kind(m, 1.5, R, 1.4, 1.9) == "hand"
    m = machine("face-hand-face")
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("robot_reach_started", 0.8, planned_duration=1.2))  # reported late, started first
    assert kind(m, 1.39, R, 1.0, 1.5) == "face"
    assert kind(m, 1.4, R, 1.0, 1.5) == "hand"  # halfway through 0.8-2.0 s
