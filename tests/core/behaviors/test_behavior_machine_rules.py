"""The gaze rules run in the ``transitions`` machine: the timer's schedule, the hold's end, the
phase rules; the tick is fed to the machine only when something can change; the diagram draws the
conditions the machine evaluates."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest
from behavior_helpers import ctx, ev, feed, hand_at

from gazebot.core.behaviors import BehaviorMachine, list_behaviors, load_behavior
from gazebot.core.behaviors.machine import diagram
from gazebot.core.types import Phase

R = Phase.REACH


def _counting(m: BehaviorMachine) -> Counter:
    """Counts the triggers ``m`` fires on its machine, by name."""
    fired: Counter = Counter()
    trigger = m._model.trigger

    def counted(name: str, *args: object) -> bool:
        fired[name] += 1
        return trigger(name, *args)

    m._model.trigger = counted
    return fired


def test_a_revised_earlier_end_estimate_starts_the_halfway_shift_on_that_tick():
    m = BehaviorMachine(load_behavior("face-hand-face"))
    feed(m, ev("reach_started", 0.0))
    assert m.target(ctx(0.1, R, 0.0, 2.0)).kind == "face"  # halfway: 1.0 s
    assert m.target(ctx(0.5, R, 0.0, 2.0)).kind == "face"
    assert m.target(ctx(0.55, R, 0.0, 1.0)).kind == "hand"  # now halfway is 0.5 s


def test_the_timer_is_fed_only_when_a_segment_can_start_or_the_evidence_changed():
    m = BehaviorMachine(load_behavior("face-hand-face"))
    fired = _counting(m)
    feed(m, ev("reach_started", 0.0))
    assert fired == {"phase": 1}
    m.target(ctx(0.01, R, 0.0, 2.0))  # the new phase is scheduled: halfway at 1.0 s
    assert fired["timer"] == 1
    for t in (0.2, 0.5, 0.99):
        assert m.target(ctx(t, R, 0.0, 2.0)).kind == "face"
    assert fired["timer"] == 1  # nothing could start before 1.0 s with that estimate
    m.target(ctx(0.995, R, 0.0, 2.2))  # a revised estimate: scheduled again (now 1.1 s)
    assert fired["timer"] == 2
    feed(m, ev("robot_reach_started", 0.0, planned_duration=3.0))  # new evidence
    m.target(ctx(1.0, R, 0.0, 2.2))
    assert fired["timer"] == 3
    assert m.target(ctx(1.5, R, 0.0, 2.2)).kind == "hand"  # halfway of the robot's 3 s
    assert fired["timer"] == 4
    for t, end in ((1.6, 2.4), (1.7, 2.6)):  # every segment of the reach started
        m.target(ctx(t, R, 0.0, end))
    assert fired["timer"] == 4


def test_the_hold_ends_by_the_machines_timer_at_its_time():
    spec = load_behavior("hand")
    m = BehaviorMachine(spec)
    fired = _counting(m)
    m.target(ctx(0.0, Phase.IDLE, 0.0))
    feed(m, ev("tracking_lost", 1.0))
    hold = spec.tracking_lost.hold_s
    before = fired["timer"]
    m.target(ctx(1.0 + hold - 0.01, Phase.IDLE, 0.0))
    assert (m.tracking, fired["timer"]) == ("hold", before)
    m.target(ctx(1.0 + hold, Phase.IDLE, 0.0))
    assert (m.tracking, fired["timer"]) == ("lost", before + 1)
    assert m.origin.target == "hand"  # the gaze state itself did not move


def _labels(definition: dict) -> set[str]:
    return {
        c.__name__ for t in definition["transitions"] for c in t.get("conditions", ())
    }


@pytest.mark.parametrize("name", [b.name for b in list_behaviors([])])
def test_the_diagram_draws_every_condition_the_running_machines_evaluate(name):
    spec = load_behavior(name)
    m = BehaviorMachine(spec)
    # The running machines evaluate exactly the conditions of their definitions.
    running = {
        c.func.__name__
        for machine in (m._machine, m.handover._machine)
        for event in machine.events.values()
        for transitions in event.transitions.values()
        for t in transitions
        for c in t.conditions
    }
    assert running == _labels(m.definition) | _labels(m.handover.definition)
    text = diagram(spec)
    for label in running:
        assert f"[{label}]" in text, label
    for rule in ("new handover", "handover done", "same handover: the gaze carries",
                 "not older than the last phase change", "after the loss"):
        assert f"[{rule}]" in text
    assert f"timer [held {spec.tracking_lost.hold_s:g} s]" in text


def test_the_handover_phase_the_machine_reads_is_its_handover_machines_state():
    m = BehaviorMachine(load_behavior("face-hand-face"))
    feed(m, ev("reach_started", 1.0))
    feed(m, ev("retreat_started", 0.5))  # stale: the handover machine's rule refuses it
    assert m.phase is R and m.handover._model.state == "reach" and m.ignored == 1
    assert math.isfinite(m.handover.phase_start)


def _script(m: BehaviorMachine, tick) -> list:
    """What ``tick(m, t)`` gives over a handover with a tracking loss (hold, then lost) and a
    hand sample that goes missing."""
    out = []
    for i in range(0, 400):
        t = i / 100
        if i == 30:
            feed(m, ev("reach_started", 0.3))
        if i == 150:
            feed(m, ev("tracking_lost", 1.5))
        if i == 250:
            feed(m, ev("tracking_restored", 2.5))
        out.append(tick(m, t))
    return out


@pytest.mark.parametrize("name", ["face-hand-face", "hand"])
def test_aim_gives_the_kind_and_point_target_gives(name):
    spec = load_behavior(name)

    def by_target(m: BehaviorMachine, t: float):
        c = ctx(t, Phase.IDLE, 0.0, hand=hand_at(t) if t < 1.0 else np.full(3, np.nan))
        got = m.target(c)
        return got.kind, got.point.tolist(), m.state

    def by_aim(m: BehaviorMachine, t: float):
        c = ctx(t, Phase.IDLE, 0.0, hand=hand_at(t) if t < 1.0 else np.full(3, np.nan))
        kind, point = m.aim(c.t, c.points, c.tracking_end)
        return kind, point.tolist(), m.state

    expected = _script(BehaviorMachine(spec, seed=1), by_target)
    assert {"reach_hand_hold", "reach_hand_lost"} <= {s for _, _, s in expected}  # both paths
    assert _script(BehaviorMachine(spec, seed=1), by_aim) == expected
