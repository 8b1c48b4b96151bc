"""The seed's reach-phase (6.3.1) and three-phase (6.4.2) pattern rules."""

from __future__ import annotations

import pytest

from gazebot.apps.annotations import GazeRule, classify_reach, classify_three_phase

f, h = "face", "hand"


@pytest.mark.parametrize(
    ("gaze", "pattern"),
    [
        ([h, h, h, h], "Hand"),
        ([f, f, f], "Face"),
        ([f, f, h, h], "Short Face-Hand"),  # face exactly half the reach: short
        ([f, f, f, h], "Long Face-Hand"),
        ([f, None, h, h], "Short Face-Hand"),  # an ignored frame inside the face gaze
        ([f, None, f, h], "Long Face-Hand"),  # ignored frames still take time
        ([h, None, h], "Hand"),  # an ignored frame does not break the pattern
        ([h, f], "other"),
        ([f, h, f], "other"),
        ([], "other"),
        ([None, None], "other"),
    ],
)
def test_reach_patterns(gaze, pattern):
    assert classify_reach(gaze) == pattern


@pytest.mark.parametrize(
    ("frames", "pattern"),
    [
        ([(h, "reach"), (h, "transfer"), (h, "retreat")], "Hand"),
        ([(h, "reach"), (h, "transfer"), (h, "retreat"), (f, "retreat")], "Hand-Face"),
        ([(h, "reach"), (f, "transfer"), (f, "retreat")], "Hand-Face"),
        ([(f, "reach"), (h, "reach"), (h, "transfer"), (f, "retreat")], "Face-Hand-Face"),
        ([(f, "reach"), (h, "reach"), (None, "retreat"), (f, "retreat")], "Face-Hand-Face"),
        ([(f, "reach"), (h, "reach"), (h, "retreat")], "other"),
        ([(f, "reach"), (f, "retreat")], "other"),
        ([(h, "reach"), (f, "transfer"), (h, "retreat")], "other"),
    ],
)
def test_three_phase_patterns(frames, pattern):
    assert classify_three_phase(frames) == pattern


def test_default_rule_counts_own_hand_as_hand_and_ignores_other():
    rule = GazeRule()
    assert [rule.target(x) for x in ("face", "hand", "own_hand", "other")] == [f, h, h, None]
    assert GazeRule(own_hand="ignore").target("own_hand") is None
    with pytest.raises(ValueError, match="own_hand"):
        GazeRule(own_hand="elbow")
