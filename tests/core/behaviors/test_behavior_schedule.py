"""The gaze timing's pure functions: segment starts, the expected phase end, which segment wins,
the phase's schedule at a tick (and when the next segment can start), the end of a hold."""

from __future__ import annotations

import math

import pytest

from gazebot.core.behaviors.schedule import (
    due_segments,
    expected_end,
    hold_over,
    schedule,
    segment_start,
)
from gazebot.core.behaviors.spec import AtEvent, AtFraction, AtNever
from gazebot.core.types import EventKind, Phase

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


HALF = AtFraction(fraction=0.5)
START = AtFraction(fraction=0.0)
AFTER_REACH_END = AtEvent(after=EventKind.ROBOT_REACH_ENDED, delay=0.2)


def test_the_schedule_starts_the_due_segments_and_follows_the_latest():
    # Reach from 1.0 s, ends (robot plan) at 3.0 s: the halfway segment starts at 2.0 s.
    plan = schedule(
        [START, HALF], [False, False], Phase.REACH, 1.0, (NAN, NAN, 3.0), 0.8, [NAN, NAN],
        2.5, -math.inf,
    )
    assert plan.starts == (1.0, 2.0) and plan.fired == (0, 1) and plan.follow == 1
    assert plan.wake == math.inf and not plan.waiting and not plan.needs_end


def test_the_schedule_wakes_at_the_next_start_and_says_what_it_depends_on():
    plan = schedule(
        [START, HALF], [False, False], Phase.REACH, 1.0, (2.0, NAN, NAN), 0.8, [NAN, NAN],
        1.2, -math.inf,
    )
    assert plan.fired == (0,) and plan.follow == 0
    # Halfway to the tracking's 2.0 s end: nothing can start before 1.5 s with this evidence.
    assert plan.wake == 1.5 and plan.waiting and plan.needs_end


def test_an_event_segment_waits_for_its_anchor_without_a_wake_time():
    plan = schedule(
        [START, AFTER_REACH_END], [True, False], Phase.REACH, 1.0, (NAN, NAN, NAN), 0.8,
        [NAN, NAN], 1.2, 1.0,
    )
    assert plan.fired == () and plan.follow is None
    assert plan.wake == math.inf and plan.waiting and not plan.needs_end
    # Once the anchor is known (1.7 s), the segment starts 0.2 s later.
    plan = schedule(
        [START, AFTER_REACH_END], [True, False], Phase.REACH, 1.0, (NAN, NAN, NAN), 0.8,
        [NAN, 1.7], 1.8, 1.0,
    )
    assert plan.wake == pytest.approx(1.9) and plan.fired == ()


def test_a_segment_never_starts_before_its_phase_and_a_never_one_never_waits():
    anchor_before_phase = 0.5
    plan = schedule(
        [AFTER_REACH_END, AtNever()], [False, False], Phase.TRANSFER, 1.0, (NAN,) * 3, 0.6,
        [anchor_before_phase, NAN], 1.0, -math.inf,
    )
    assert plan.starts[0] == 1.0 and plan.fired == (0,) and plan.follow == 0
    assert math.isnan(plan.starts[1]) and not plan.waiting


def test_the_hold_is_over_once_it_lasted_its_time():
    assert not hold_over(2.0, 0.5, 2.49)
    assert hold_over(2.0, 0.5, 2.5)
    assert not hold_over(NAN, 0.5, 9.0)  # no loss: no hold to end
