"""The behavior's gaze timing as pure functions: when each segment of a phase starts, the
phase's expected end, which segment the gaze follows at a time, and when a tracking-loss hold
is over.

The behavior machine (:mod:`gazebot.core.behaviors.machine`) calls these from its ``timer``
transitions (:func:`schedule` from their ``prepare`` callback, :func:`hold_over` as the hold's
condition); they keep no state, so each rule is unit-tested on its own.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from gazebot.core.behaviors.segment import AtEvent, AtFraction, AtNever
from gazebot.core.types import Phase


def expected_end(
    phase: Phase, start: float, estimates: Sequence[float], default_s: float
) -> float:
    """The current phase's expected end (s), for fraction timings ("halfway").

    ``estimates`` are, in order of trust: the tracking's prediction (the phase detector's), the
    phase event's own ``expected_end``, the robot's motion plan (its start + planned duration).
    Only finite ends after ``start`` count; with none, ``start + default_s`` (the behavior's
    ``phase_durations_s``). A reach ends when both hands have arrived: the latest estimate
    wins. Any other phase (a retreat ends when the giver's hand is back at rest, usually before
    the robot is home) takes the first known estimate.
    """
    known = [end for end in estimates if math.isfinite(end) and end > start]
    if not known:
        return start + default_s
    if phase is Phase.REACH:
        return max(known)
    return known[0]


def end_rule(phase: Phase, default_s: float) -> str:
    """:func:`expected_end`'s rule for ``phase`` in words (the diagram's label)."""
    pick = "latest" if phase is Phase.REACH else "first known"
    return f"end: {pick} of tracking, event, robot plan; else {default_s:g} s"


def segment_start(
    at: AtFraction | AtEvent | AtNever, phase_start: float, end: float, anchor: float
) -> float:
    """When a segment starts (s): ``phase_start`` plus its fraction of the phase up to
    ``end``, or its anchor event's time (``anchor``, NaN if it did not happen yet) plus its
    delay; NaN for ``never`` or an anchor not yet seen."""
    if isinstance(at, AtFraction):
        return phase_start + at.fraction * (end - phase_start)
    if isinstance(at, AtEvent):
        return anchor + at.delay
    return math.nan


def due_segments(
    starts: Sequence[float], started: Sequence[bool], t: float, latest: float
) -> tuple[list[int], int | None]:
    """Which segments start by ``t`` and which one the gaze follows.

    Args:
        starts: Each segment's start (s; NaN: not known yet, or never).
        started: Whether each segment already started (a started segment stays started: a
            revised estimate never moves the gaze back).
        t: Now (s).
        latest: Start (s) of the segment the gaze follows now.

    Returns:
        The indices that start now, and the one the gaze follows among them: **the latest start
        wins** (a tie: the later segment), or ``None`` when none starts or all of them start
        before ``latest``.
    """
    fired: list[int] = []
    best, best_t = None, latest
    for i, (start, done) in enumerate(zip(starts, started, strict=True)):
        if done or not start <= t:  # (NaN compares false: not yet)
            continue
        fired.append(i)
        if start >= best_t:
            best, best_t = i, start
    return fired, best


@dataclass(frozen=True)
class Schedule:
    """The current phase's segments at one tick (:func:`schedule`).

    Attributes:
        starts: Each segment's start (s; NaN: not known yet, or never).
        fired: The segments that start at this tick.
        follow: The one the gaze follows among them (the latest start), ``None`` if none.
        wake: The earliest start (s) of a segment still waiting after this tick, ``inf`` if
            none is known: before it, with the same evidence, nothing can start.
        waiting: Some segment may still start after this tick (a ``never`` one cannot).
        needs_end: Some waiting segment's start depends on the phase's expected end.
    """

    starts: tuple[float, ...]
    fired: tuple[int, ...]
    follow: int | None
    wake: float
    waiting: bool
    needs_end: bool


def schedule(
    timings: Sequence[AtFraction | AtEvent | AtNever],
    started: Sequence[bool],
    phase: Phase,
    phase_start: float,
    estimates: Sequence[float],
    default_s: float,
    anchors: Sequence[float],
    t: float,
    latest: float,
) -> Schedule:
    """The current phase's segments at ``t``: each one's start (:func:`segment_start`, never
    before the phase's start, with the end from :func:`expected_end`), which start now and
    which one the gaze follows (:func:`due_segments`), and the earliest time the next one can.

    Args:
        timings: Each segment's ``at``, in the phase's order.
        started: Whether each segment already started.
        phase: The current phase.
        phase_start: Its start (s).
        estimates: The estimates of its end (see :func:`expected_end`).
        default_s: The behavior's duration of the phase (s), without an estimate.
        anchors: Per segment, when its ``after`` event happened in this handover (s; NaN: not
            yet, or not an event timing).
        t: Now (s).
        latest: Start (s) of the segment the gaze follows now.
    """
    fractions = [isinstance(at, AtFraction) for at in timings]
    end = (
        expected_end(phase, phase_start, estimates, default_s) if any(fractions) else math.nan
    )
    starts = tuple(
        max(segment_start(at, phase_start, end, anchor), phase_start)  # NaN stays NaN
        for at, anchor in zip(timings, anchors, strict=True)
    )
    fired, follow = due_segments(starts, started, t, latest)
    wake, waiting, needs_end = math.inf, False, False
    for i, at in enumerate(timings):
        if started[i] or i in fired or isinstance(at, AtNever):
            continue
        waiting = True
        needs_end = needs_end or fractions[i]
        if starts[i] < wake:  # (NaN compares false: not known yet)
            wake = starts[i]
    return Schedule(starts, tuple(fired), follow, wake, waiting, needs_end)


def hold_over(lost_since: float, hold_s: float, t: float) -> bool:
    """Whether a tracking-loss hold that began at ``lost_since`` (s) and lasts ``hold_s`` is
    over at ``t``: the gaze then leaves the held point for the behavior's ``tracking_lost``
    target."""
    return t >= lost_since + hold_s
