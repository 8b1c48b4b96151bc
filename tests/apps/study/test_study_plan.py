"""Counterbalanced study plans: Table 6.4 pairings, Williams balance, validation, CSV round trip."""

from __future__ import annotations

import itertools
from collections import Counter

import numpy as np
import pytest

from gazebot.apps.study.plan import (
    CONDITION_LEVELS,
    DEFAULT_BEHAVIORS,
    check_balance,
    make_plan,
    ordered_pairings,
    read_plan,
    williams_square,
    write_plan,
)


def test_ordered_pairings_follow_seed_table_6_4():
    assert ordered_pairings(["hand-face", "face-hand-face", "hand"]) == [
        ("hand-face", "face-hand-face"),
        ("hand-face", "hand"),
        ("face-hand-face", "hand"),
        ("face-hand-face", "hand-face"),
        ("hand", "hand-face"),
        ("hand", "face-hand-face"),
    ]


@pytest.mark.parametrize("k", [2, 4, 6, 12])
def test_williams_square_is_latin_and_carryover_balanced(k):
    sq = williams_square(k)
    for line in list(sq) + list(sq.T):
        assert sorted(line) == list(range(k))
    follows = Counter((a, b) for row in sq for a, b in itertools.pairwise(row))
    assert set(follows) == {(a, b) for a in range(k) for b in range(k) if a != b}
    assert set(follows.values()) == {1}


@pytest.mark.parametrize("condition", sorted(CONDITION_LEVELS))
def test_plan_of_24_gives_each_participant_all_12_sessions_once(condition):
    plan = make_plan(condition=condition, participants=24, seed=5)
    assert len(plan) == 24 * 12
    levels = set(CONDITION_LEVELS[condition])
    for p in range(1, 25):
        rows = sorted((s for s in plan if s.participant == p), key=lambda s: s.session)
        assert [s.session for s in rows] == list(range(1, 13))
        keys = {s.key for s in rows}
        assert len(keys) == 12
        assert {s.level for s in rows} == levels
        for level in levels:
            assert sorted((s.first, s.second) for s in rows if s.level == level) == sorted(
                ordered_pairings(list(DEFAULT_BEHAVIORS))
            )
    assert {s.gaze_mode for s in plan} == {"eyes-only"}  # 6.4: "robot eye gazes"


def test_seed_6_3_design_plans_every_ordered_pair_of_four_behaviors_once():
    """6.3.2: "The 12 sessions consisted of the six possible pairings of the four gaze patterns
    and their reverse order", no condition, 24 participants."""
    behaviors = ["face", "hand", "short-face-hand", "long-face-hand"]
    plan = make_plan(behaviors, condition=None, participants=24, seed=3)
    assert len(plan) == 24 * 12
    for p in range(1, 25):
        rows = sorted((s for s in plan if s.participant == p), key=lambda s: s.session)
        assert [s.session for s in rows] == list(range(1, 13))
        assert sorted((s.first, s.second) for s in rows) == sorted(
            itertools.permutations(behaviors, 2)
        )
        assert {(s.condition, s.level, s.scene) for s in rows} == {("", "", "robot-initiated")}
    assert {s.gaze_mode for s in plan} == {"head-only"}  # 6.3.2: static eyes on a moving head
    report = check_balance(plan)
    assert report.position_balanced and report.carryover_balanced


def test_plan_without_condition_round_trips_through_csv_with_empty_level(tmp_path):
    plan = make_plan(["face", "hand"], condition=None, participants=4, gaze_mode="eyes-only")
    assert read_plan(write_plan(plan, tmp_path / "p.csv")) == plan


def test_each_session_appears_once_per_position_in_every_block_of_12():
    plan = make_plan(participants=36, seed=11)
    for block in range(3):
        members = range(block * 12 + 1, block * 12 + 13)
        report = check_balance([s for s in plan if s.participant in members])
        assert report.position_balanced and report.carryover_balanced
        assert set(report.position_counts.values()) == {1}
    full = check_balance(plan)
    assert full.position_balanced
    assert set(full.position_counts.values()) == {3}


def test_plan_is_randomised_by_seed_and_reproducible():
    a = make_plan(participants=12, seed=1)
    assert make_plan(participants=12, seed=1) == a
    b = make_plan(participants=12, seed=2)
    assert [s.key for s in a] != [s.key for s in b]
    first_sessions = {s.key for s in a if s.session == 1}
    assert len(first_sessions) == 12  # every participant starts with a different session


def test_balance_check_detects_unbalanced_plan():
    plan = make_plan(participants=12, seed=0)
    # Give participant 2 participant 1's order: positions are no longer balanced.
    order1 = [s for s in plan if s.participant == 1]
    broken = [s for s in plan if s.participant != 2] + [
        type(s)(**{**s.__dict__, "participant": 2}) for s in order1
    ]
    report = check_balance(broken)
    assert not report.position_balanced


@pytest.mark.parametrize("n", [0, -12, 5, 13, 18])
def test_participant_count_must_be_a_full_block_multiple(n):
    with pytest.raises(ValueError, match="multiple of 12"):
        make_plan(participants=n)


def test_block_size_follows_number_of_behaviors():
    plan = make_plan(behaviors=["a", "b"], participants=4, seed=0)
    assert check_balance(plan).position_balanced
    with pytest.raises(ValueError, match="multiple of 4"):
        make_plan(behaviors=["a", "b"], participants=6)


def test_unknown_condition_and_duplicate_behaviors_are_rejected():
    with pytest.raises(ValueError, match="unknown condition"):
        make_plan(condition="color", participants=12)
    with pytest.raises(ValueError, match="distinct"):
        make_plan(behaviors=["hand", "hand", "face"], participants=12)


def test_scene_mapping_and_csv_round_trip(tmp_path):
    plan = make_plan(
        condition="posture",
        participants=12,
        seed=3,
        robot="jaco2",
        scenes={"sitting": "office-chair"},
        video_seed=7,
    )
    path = write_plan(plan, tmp_path / "plan.csv")
    back = read_plan(path)
    assert back == plan
    assert {s.scene for s in back} == {"office-chair", "standing"}
    assert {s.scene for s in make_plan(condition="fragility", participants=12)} == {
        "fragile",
        "non-fragile",
    }
    assert {s.robot for s in back} == {"jaco2"} and {s.video_seed for s in back} == {7}


def test_read_plan_reports_bad_rows(tmp_path):
    path = tmp_path / "plan.csv"
    write_plan(make_plan(participants=12), path)
    lines = path.read_text().splitlines()
    parts = lines[3].split(",")
    parts[1] = "x"
    lines[3] = ",".join(parts)
    path.write_text("\n".join(lines))
    with pytest.raises(ValueError, match="line 4: column 'session'"):
        read_plan(path)
    (tmp_path / "bad.csv").write_text("participant,session\n1,1\n")
    with pytest.raises(ValueError, match="missing column"):
        read_plan(tmp_path / "bad.csv")
    with pytest.raises(FileNotFoundError):
        read_plan(tmp_path / "none.csv")


def test_relabelling_keeps_positions_uniform_over_many_seeds():
    # Property over seeds: any full block is position-balanced.
    for seed in range(20):
        report = check_balance(make_plan(participants=12, seed=seed))
        assert report.position_balanced and report.carryover_balanced
    assert np.all(williams_square(12)[0] == [0, 1, 11, 2, 10, 3, 9, 4, 8, 5, 7, 6])
