"""The gaze timing's pure functions: segment starts, the expected phase end, which segment wins."""

from __future__ import annotations

import math

from gazebot.behaviors.schedule import due_segments, expected_end, segment_start
from gazebot.behaviors.spec import AtEvent, AtFraction, AtNever
from gazebot.types import EventKind, Phase

NAN = math.nan


def test_a_reach_ends_with_the_latest_estimate_a_retreat_with_the_first_known():
    estimates = (2.0, NAN, 2.4)  # tracking, event, robot plan
    assert expected_end(Phase.REACH, 1.0, estimates, 0.8) == 2.4
    assert expected_end(Phase.RETREAT, 1.0, estimates, 1.05) == 2.0
    assert expected_end(Phase.RETREAT, 1.0, (NAN, 3.0, 2.4), 1.05) == 3.0


def test_without_an_estimate_after_the_start_the_behaviors_default_duration_counts():
    assert expected_end(Phase.REACH, 1.0, (NAN, 0.5, NAN), 0.8) == 1.8  # 0.5 is before the start


def test_segment_starts_from_fractions_anchors_and_never():
    assert segment_start(AtFraction(fraction=0.5), 1.0, 2.0, NAN) == 1.5
    at = AtEvent(after=EventKind.ROBOT_REACH_ENDED, delay=0.2)
    assert segment_start(at, 1.0, 2.0, 1.7) == 1.9
    assert math.isnan(segment_start(at, 1.0, 2.0, NAN))  # the anchor did not happen yet
    assert math.isnan(segment_start(AtNever(), 1.0, 2.0, 1.7))


def test_the_latest_start_wins_and_a_tie_goes_to_the_later_segment():
    fired, best = due_segments([1.0, 1.5, 1.5, 3.0], [False] * 4, 2.0, -math.inf)
    assert fired == [0, 1, 2] and best == 2


def test_started_and_unknown_segments_do_not_fire_again():
    fired, best = due_segments([1.0, NAN, 1.2], [True, False, False], 2.0, 1.0)
    assert fired == [2] and best == 2
    fired, best = due_segments([1.0, NAN], [True, False], 5.0, 1.0)
    assert fired == [] and best is None


def test_a_segment_starting_before_the_followed_one_does_not_take_the_gaze_back():
    # A revised estimate makes an earlier segment due late: it starts, the gaze stays.
    fired, best = due_segments([1.2], [False], 2.0, 1.5)
    assert fired == [0] and best is None
