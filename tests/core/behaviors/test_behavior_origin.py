"""The behavior records the rule that picked its gaze when it picked it (review finding 4): the
phase-agreement test over the simulated scenes (tests/apps/sim/test_sim_phase_agreement.py) relies
on it, and on the check catching an origin that does not match the command."""

from __future__ import annotations

from dataclasses import replace

from behavior_helpers import ctx, ev, feed

from gazebot.core.behaviors import BehaviorMachine, GazeOrigin, load_behavior
from gazebot.core.types import Phase


def _face_hand_face() -> BehaviorMachine:
    return BehaviorMachine(load_behavior("face-hand-face"), seed=0)


def _look(m: BehaviorMachine, t: float) -> str:
    return m.target(ctx(t, m.phase, 0.0)).kind


def test_a_segment_records_its_own_phase_and_a_carry_keeps_it():
    m = _face_hand_face()
    assert m.origin == GazeOrigin(Phase.IDLE, "before", "face")
    feed(m, ev("reach_started", 1.0))
    assert (m.origin.phase, m.origin.rule, m.origin.carried_into) == (Phase.REACH, "before", None)
    feed(m, ev("robot_reach_started", 1.0, planned_duration=1.0))
    assert _look(m, 1.6) == "hand"
    picked = m.origin
    assert (picked.phase, picked.rule, picked.target) == (Phase.REACH, "segment 1", "hand")
    assert 1.5 <= picked.t <= 1.6
    feed(m, ev("transfer_started", 2.0))
    # the transfer keeps the hand until its own segment fires: the gaze is the reach's, carried
    assert m.origin == replace(picked, carried_into=Phase.TRANSFER)
    assert m.origin_disagreement(Phase.TRANSFER, "hand") is None
    assert m.origin_disagreement(Phase.REACH, "hand") is not None  # carried into transfer


def test_a_stale_origin_is_caught():
    m = _face_hand_face()
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("robot_reach_started", 1.0, planned_duration=1.0))
    before = m.origin  # the reach's "before" rule: the face
    assert _look(m, 1.6) == "hand"
    picked = m.origin
    # An origin not updated when the segment picked the hand (stale): wrong target.
    m.origin = before
    assert "target 'hand'" in m.origin_disagreement(Phase.REACH, "hand")
    m.origin = picked
    feed(m, ev("transfer_started", 2.0))
    carried = m.origin
    assert carried.carried_into is Phase.TRANSFER and m.origin_disagreement(
        Phase.TRANSFER, "hand") is None
    # The old labelling: a gaze carried from the reach, stamped with the transfer's phase.
    m.origin = replace(carried, phase=Phase.TRANSFER, carried_into=None)
    assert "transfer has no segment 1 looking at 'hand'" in m.origin_disagreement(
        Phase.TRANSFER, "hand")
    # The reach's rule left unmarked after the phase moved on: not the reported phase.
    m.origin = replace(carried, carried_into=None)
    assert "reported transfer, but the target is segment 1 of reach" in m.origin_disagreement(
        Phase.TRANSFER, "hand")
    # Carried into a phase other than the reported one.
    m.origin = replace(carried, carried_into=Phase.RETREAT)
    assert m.origin_disagreement(Phase.TRANSFER, "hand") is not None
