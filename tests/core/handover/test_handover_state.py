"""The one handover state: the phase stream merged from the detector's and the robot's events."""

from __future__ import annotations

import math

import pytest

from gazebot.core.handover import RULES, HandoverState, PhaseChange, apply_event
from gazebot.core.types import Event, EventKind, Phase


def ev(kind: str, t: float, **info) -> Event:
    return Event(EventKind(kind), t, t, dict(info))


def test_the_robots_reach_starts_the_reach_and_the_givers_later_one_only_joins_it():
    s = HandoverState()
    change = s.apply(ev("robot_reach_started", 0.5, planned_duration=1.2))
    assert change is not None and change.new_handover and change.source == "robot"
    assert (s.phase, s.phase_start, s.source) == (Phase.REACH, 0.5, "robot")
    assert s.apply(ev("reach_started", 1.0)) is None  # the giver responds: same handover
    assert (s.phase, s.phase_start, s.handover, s.ignored) == (Phase.REACH, 0.5, 0, 0)


def test_the_first_reach_wins_even_when_reported_late():
    s = HandoverState()
    s.apply(ev("reach_started", 1.0))
    s.apply(ev("robot_reach_started", 0.8, planned_duration=1.2))  # started first, told later
    assert (s.phase_start, s.source) == (0.8, "robot")
    assert s.robot_motion_end() == pytest.approx(2.0)


def test_the_givers_earlier_reach_told_after_the_robots_takes_the_start_and_the_source():
    # Review finding 10a: robot 0.8 s, then the giver's reach at 0.5 s is reported.
    s = HandoverState()
    s.apply(ev("robot_reach_started", 0.8, planned_duration=1.2))
    assert (s.phase_start, s.source) == (0.8, "robot")
    assert s.apply(ev("reach_started", 0.5)) is None  # not a new phase: the reach only moves
    assert (s.phase, s.phase_start, s.source, s.handover) == (Phase.REACH, 0.5, "tracking", 0)
    assert s.robot_motion_end() == pytest.approx(2.0)  # the robot's plan still counts


def test_a_later_reach_of_the_other_party_keeps_the_start_and_the_source():
    s = HandoverState()
    s.apply(ev("reach_started", 0.5))
    s.apply(ev("robot_reach_started", 0.8))
    assert (s.phase_start, s.source) == (0.5, "tracking")


def test_a_duplicate_reach_of_the_same_party_keeps_the_first_time():
    s = HandoverState()
    s.apply(ev("reach_started", 1.0))
    s.apply(ev("reach_started", 1.4))
    assert s.phase_start == 1.0 and s.ignored == 1


@pytest.mark.parametrize("start", [Phase.IDLE, Phase.REACH, Phase.DONE])
def test_the_grasp_is_transfer_evidence(start):
    s = HandoverState()
    if start is not Phase.IDLE:
        s.apply(ev("reach_started", 1.0))
    if start is Phase.DONE:
        s.apply(ev("handover_done", 1.5))
    change = s.apply(ev("robot_grasped", 2.0))
    assert change is not None and change.phase is Phase.TRANSFER and change.source == "gripper"
    assert change.new_handover is (start is not Phase.REACH)
    # The detector's transfer, seen later, is the same phase: nothing changes.
    assert s.apply(ev("transfer_started", 2.1)) is None and s.phase_start == 2.0


def test_the_robots_release_ends_the_transfer():
    s = HandoverState()
    s.apply(ev("robot_reach_started", 1.0))
    s.apply(ev("robot_grasped", 2.0))
    change = s.apply(ev("robot_released", 2.6))
    assert change is not None and change.phase is Phase.RETREAT and not change.new_handover
    assert s.apply(ev("robot_released", 5.0)) is None  # not in a transfer: no phase move


def test_the_detectors_gripper_evidence_is_reported_as_the_gripper():
    s = HandoverState()
    s.apply(ev("reach_started", 1.0, source="gripper"))
    s.apply(ev("transfer_started", 1.0, source="load_share"))
    assert s.source == "gripper"
    s.apply(ev("retreat_started", 2.0, source="motion"))
    assert s.source == "tracking"


def test_stale_and_disallowed_phase_events_are_ignored_and_counted():
    s = HandoverState()
    s.apply(ev("transfer_started", 2.0))
    assert s.apply(ev("retreat_started", 1.5)) is None  # older than the transfer
    assert s.apply(ev("transfer_started", 2.5)) is None  # duplicate
    assert s.apply(Event(EventKind.REACH_STARTED, math.nan, math.nan)) is None
    assert s.apply(Event("nope", 3.0, 3.0)) is None  # type: ignore[arg-type]
    assert s.phase is Phase.TRANSFER and s.ignored == 4


def test_a_reach_after_a_missed_done_starts_a_new_handover_without_the_old_robot_events():
    s = HandoverState()
    s.apply(ev("reach_started", 1.0))
    s.apply(ev("robot_reach_ended", 1.8))
    s.apply(ev("retreat_started", 2.5))
    change = s.apply(ev("reach_started", 6.0))
    assert change is not None and change.new_handover and s.handover == 1
    assert math.isnan(s.anchor(EventKind.ROBOT_REACH_ENDED))
    assert s.anchor(EventKind.REACH_STARTED) == 6.0


def test_would_move_tells_the_time_of_a_phase_change_without_changing_anything():
    s = HandoverState()
    assert s.would_move(ev("reach_started", 1.0)) == 1.0
    assert s.would_move(ev("robot_reach_ended", 1.0)) is None
    assert s.phase is Phase.IDLE and s.ignored == 0


def test_every_rule_is_reachable_from_its_sources():
    for rule in RULES:
        for source in rule.sources:
            assert rule.dest is None or rule.dest is not source, rule


def test_the_machine_is_built_from_the_rule_table():
    s = HandoverState()
    assert s.definition["states"] == [p.value for p in Phase]
    rows = [(r, src) for r in RULES for src in r.sources]
    transitions = s.definition["transitions"]
    assert len(transitions) == len(rows)
    for (rule, source), t in zip(rows, transitions, strict=True):
        assert (t["trigger"], t["source"]) == (rule.trigger.value, source.value)
        assert t["dest"] == (rule.dest.value if rule.dest is not None else None)  # None: stays
        assert [c.__name__ for c in t["conditions"]] == [rule.condition]


# How to be in each phase of a handover whose last change was at 1.0 s (in a reach: the other
# party's reach start than the rule's).
_INTO = {
    Phase.IDLE: [],
    Phase.REACH: [("robot_reach_started", 1.0)],
    (Phase.REACH, EventKind.ROBOT_REACH_STARTED): [("reach_started", 1.0)],
    Phase.TRANSFER: [("transfer_started", 1.0)],
    Phase.RETREAT: [("retreat_started", 1.0)],
    Phase.DONE: [("reach_started", 0.5), ("handover_done", 1.0)],
}


@pytest.mark.parametrize(
    ("rule", "source"), [(r, src) for r in RULES for src in r.sources],
    ids=lambda x: x.value if isinstance(x, Phase) else x.trigger.value,
)
def test_every_row_of_the_table_does_what_it_says(rule, source):
    s = HandoverState()
    for kind, t in _INTO.get((source, rule.trigger), _INTO[source]):
        s.apply(ev(kind, t))
    assert s.phase is source
    start = s.phase_start
    if rule.dest is None:  # the other party's reach: the phase stays, its start moves earlier
        assert s.would_move(ev(rule.trigger.value, 0.8)) is None
        assert s.apply(ev(rule.trigger.value, 0.8)) is None
        assert (s.phase, s.phase_start, s.ignored) == (source, 0.8, 0)
        return
    if source is not Phase.IDLE:
        stale = ev(rule.trigger.value, 0.9)  # older than the last phase change
        assert s.would_move(stale) is None and s.apply(stale) is None and s.phase is source
        assert s.phase_start == start
    assert s.would_move(ev(rule.trigger.value, 2.0)) == 2.0
    change = s.apply(ev(rule.trigger.value, 2.0))
    assert change is not None and change.rule == rule
    assert (s.phase, s.phase_start, change.previous) == (rule.dest, 2.0, source)


def test_entry_counts_the_phases_the_tracking_follows():
    s = HandoverState()
    first = s.entry
    s.apply(ev("robot_reach_started", 1.0, planned_duration=1.0))
    # A reach only the robot started: the tracking has not shown it (its reach is still due).
    assert (s.phase, s.reach_tracked, s.entry) == (Phase.REACH, False, first)
    s.apply(ev("reach_started", 1.2))  # the giver's joins it (later: the start stays)
    assert (s.phase_start, s.reach_tracked, s.entry) == (1.0, True, first + 1)
    s.apply(ev("robot_grasped", 2.0))
    assert (s.phase, s.entry) == (Phase.TRANSFER, first + 2)
    s.apply(ev("transfer_started", 1.9))  # stale: nothing entered
    assert s.entry == first + 2


class _Follower:
    def __init__(self) -> None:
        self.calls: list[tuple[str, object]] = []

    def advance(self, t: float) -> None:
        self.calls.append(("advance", t))

    def on_phase(self, change: PhaseChange) -> None:
        self.calls.append(("phase", change.phase))

    def on_tracking(self, event: Event) -> None:
        self.calls.append(("tracking", event.kind))


def test_apply_event_lets_the_follower_catch_up_then_tells_it_the_change():
    s, f = HandoverState(), _Follower()
    assert apply_event(s, f, ev("reach_started", 1.0)) is not None
    assert f.calls == [("advance", 1.0), ("phase", Phase.REACH)]
    f.calls.clear()
    assert apply_event(s, f, ev("tracking_lost", 1.5)) is None
    assert f.calls == [("tracking", EventKind.TRACKING_LOST)] and s.phase is Phase.REACH
    f.calls.clear()
    assert apply_event(s, f, ev("reach_started", 0.5)) is None  # a duplicate: nothing to tell
    assert apply_event(s, f, ev("robot_reach_ended", 1.6)) is None  # evidence, no phase change
    assert f.calls == []
