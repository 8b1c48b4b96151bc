"""Replaying annotated phases through behaviors (synthetic handovers)."""

from __future__ import annotations

from annotation_helpers import handover_rows, write_xlsx

from gazebot.apps.annotations import load_handover, replay_handover
from gazebot.apps.annotations.replay import handover_events
from gazebot.core.behaviors import load_behavior
from gazebot.core.types import EventKind


def test_phase_labels_become_detector_and_robot_events():
    phases = ("other", "reach", "reach", "transfer", "retreat", "retreat", "other")
    events = handover_events(phases)
    kinds = {i: [e.kind for e in evs] for i, evs in events.items()}
    assert kinds[1] == [EventKind.REACH_STARTED, EventKind.ROBOT_REACH_STARTED]
    assert events[1][1].info["planned_duration"] == 2 / 8
    assert EventKind.TRANSFER_STARTED in kinds[3] and EventKind.ROBOT_REACH_ENDED in kinds[3]
    assert EventKind.RETREAT_STARTED in kinds[4]
    assert EventKind.HANDOVER_DONE in kinds[6]


def test_face_hand_face_matches_a_face_hand_face_receiver_exactly(tmp_path):
    # The synthetic receiver: reach F F F H H H (switch at half), transfer hand/own hand,
    # retreat O O O F F F (switch at half).
    h = load_handover(write_xlsx(tmp_path / "a 1.xlsx", handover_rows()))
    result = replay_handover(h, load_behavior("face-hand-face"), "receiver")
    assert result.compared == 15 and result.matched == 15
    face = replay_handover(h, load_behavior("face"), "receiver")
    assert face.matched == 6  # 3 reach + 3 retreat face frames
    assert face.by_phase["transfer"] == (0, 3)


def test_giver_role_ignores_other_frames(tmp_path):
    h = load_handover(write_xlsx(tmp_path / "a 1.xlsx", handover_rows()))
    result = replay_handover(h, load_behavior("hand"), "giver")
    assert result.compared == 14  # one Other frame in the retreat is skipped
    assert result.matched == 10
