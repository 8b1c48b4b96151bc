"""Property-based: any event stream (duplicated, missing, out of order, odd times) is handled."""

from __future__ import annotations

import math

import numpy as np
from behavior_helpers import feed, points
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gazebot.core.behaviors import BehaviorMachine, list_behaviors, load_behavior
from gazebot.core.behaviors.machine import Tick
from gazebot.core.types import Event, EventKind, GazeContext, Phase

SPECS = {info.name: load_behavior(info.name) for info in list_behaviors([])}
# One machine per behavior, reset per example: building a machine costs milliseconds.
MACHINES = {name: BehaviorMachine(spec) for name, spec in SPECS.items()}

times = st.one_of(
    st.floats(min_value=-5.0, max_value=20.0, allow_nan=False),
    st.sampled_from([math.nan, math.inf, -math.inf, 0.0]),
)
events = st.builds(
    lambda kind, t, dt, planned: Event(
        kind, t, t + dt, {"planned_duration": planned} if planned is not None else {}
    ),
    st.sampled_from(list(EventKind)),
    times,
    st.floats(min_value=0.0, max_value=1.0),
    st.one_of(st.none(), times, st.just(-1.0)),
)
maybe_nan_point = st.one_of(
    st.none(),
    st.just(np.full(3, np.nan)),
    st.lists(st.floats(-2, 2), min_size=3, max_size=3).map(np.array),
)
contexts = st.builds(
    lambda t, phase, start, end, hand, face: (t, phase, start, end, hand, face),
    times,
    st.sampled_from(list(Phase)),
    times,
    times,
    maybe_nan_point,
    maybe_nan_point,
)
steps = st.lists(st.one_of(events, contexts), max_size=40)


def _ctx(t, phase, start, end, hand, face) -> GazeContext:
    pts = points(0.0)
    if hand is not None:
        pts["hand"] = hand
    if face is not None:
        pts["face"] = face
    return GazeContext(t, pts, tracking_end=end)


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True
)
@given(name=st.sampled_from(sorted(SPECS)), seed=st.integers(0, 2**16), script=steps)
def test_any_event_sequence_never_raises_and_always_yields_a_valid_target(name, seed, script):
    m = MACHINES[name]
    m.reset(seed)
    allowed = SPECS[name].targets()
    for step in script:
        if isinstance(step, Event):
            feed(m, step)
        else:
            c = _ctx(*step)
            target = m.target(c)
            assert target.kind in allowed
            assert np.shape(target.point) == (3,)
            if all(np.all(np.isfinite(c.points[k])) for k in ("face", "rest")):
                assert np.all(np.isfinite(target.point))
            assert m.state.startswith(m.phase.value + "_")
        assert m.state in m.states


@settings(max_examples=100, deadline=None, derandomize=True)
@given(
    name=st.sampled_from(sorted(SPECS)),
    order=st.permutations(list(range(7))),
    dup=st.lists(st.integers(0, 6), max_size=4),
)
def test_shuffled_and_duplicated_handover_events_end_in_a_defined_state(name, order, dup):
    base = [
        Event(EventKind.REACH_STARTED, 1.0, 1.0),
        Event(EventKind.ROBOT_REACH_STARTED, 1.0, 1.0, {"planned_duration": 1.0}),
        Event(EventKind.TRANSFER_STARTED, 2.0, 2.0),
        Event(EventKind.ROBOT_REACH_ENDED, 2.0, 2.0),
        Event(EventKind.RETREAT_STARTED, 2.5, 2.5),
        Event(EventKind.ROBOT_RETREAT_STARTED, 2.5, 2.5, {"planned_duration": 1.0}),
        Event(EventKind.HANDOVER_DONE, 3.5, 3.5),
    ]
    m = MACHINES[name]
    m.reset(0)
    for i in list(order) + list(dup):
        feed(m, base[i])
        assert m.state in m.states
    # Whatever arrived late was ignored; the handover ends with the next (in-order) report.
    feed(m, Event(EventKind.HANDOVER_DONE, 4.0, 4.0))
    assert m.target(_ctx(4.0, Phase.DONE, 3.5, math.nan, None, None)).kind == SPECS[name].after
    assert m.state.startswith("done_")


class _TimerEveryTick(BehaviorMachine):
    """A machine fed the ``timer`` trigger on every tick (no tick skipped)."""

    def advance(self, t: float, tracking_end: float | None = None) -> None:
        if tracking_end is not None:
            self._tracking_end = tracking_end
        self._model.trigger("timer", Tick(t, self._tracking_end))


EVERY_TICK = {name: _TimerEveryTick(spec) for name, spec in SPECS.items()}
_HANDOVER = (
    EventKind.ROBOT_REACH_STARTED,
    EventKind.REACH_STARTED,
    EventKind.ROBOT_REACH_ENDED,
    EventKind.ROBOT_GRASPED,
    EventKind.TRANSFER_STARTED,
    EventKind.ROBOT_RETREAT_STARTED,
    EventKind.RETREAT_STARTED,
    EventKind.ROBOT_RELEASED,
    EventKind.TRACKING_LOST,
    EventKind.TRACKING_RESTORED,
    EventKind.HANDOVER_DONE,
)


@st.composite
def handover_steps(draw) -> list:
    """A handover-like stream: its events (each maybe missing, at jittered times, a planned
    duration for the robot's motions) and ticks every 25 ms with revised end estimates."""
    out: list = []
    for i, kind in enumerate(_HANDOVER * draw(st.integers(1, 2))):
        if draw(st.booleans()) or draw(st.booleans()):
            t = 0.4 * i + draw(st.floats(-0.3, 0.3))
            planned = draw(st.one_of(st.none(), st.floats(0.1, 2.0)))
            out.append((t, Event(kind, t, t, {} if planned is None else
                                 {"planned_duration": planned})))
    ends = draw(st.lists(st.one_of(st.just(math.nan), st.floats(-0.2, 1.5)), min_size=1))
    for k in range(int(0.4 * 2 * len(_HANDOVER) / 0.025)):
        t = 0.025 * k
        out.append((t, (t, Phase.IDLE, 0.0, t + ends[(k // 8) % len(ends)], None, None)))
    out.sort(key=lambda item: item[0])
    return [item for _, item in out]


@settings(max_examples=150, deadline=None, derandomize=True)
@given(
    name=st.sampled_from(sorted(SPECS)),
    seed=st.integers(0, 2**16),
    script=st.one_of(handover_steps(), steps),
)
def test_a_skipped_timer_tick_never_changes_a_decision(name, seed, script):
    # The machine skips the timer trigger while its last schedule says nothing can start; a
    # machine triggered on every tick must pick the same targets by the same rules.
    fed, skipping = EVERY_TICK[name], MACHINES[name]
    fed.reset(seed)
    skipping.reset(seed)
    for step in script:
        if isinstance(step, Event):
            feed(fed, step)
            feed(skipping, step)
            continue
        c = _ctx(*step)
        a, b = fed.target(c), skipping.target(c)
        assert a.kind == b.kind and np.array_equal(a.point, b.point, equal_nan=True)
        assert (fed.state, fed.origin, fed.ignored) == (skipping.state, skipping.origin,
                                                        skipping.ignored)


def test_a_duplicated_reach_start_keeps_the_first_start_time():
    m = BehaviorMachine(SPECS["face-hand-face"])
    feed(m, Event(EventKind.REACH_STARTED, 1.0, 1.0))
    feed(m, Event(EventKind.REACH_STARTED, 1.4, 1.4))
    assert m.ignored == 1
    kind = m.target(GazeContext(1.55, points(1.55), tracking_end=2.0)).kind
    assert kind == "hand"  # halfway of 1.0-2.0 s, not of 1.4-2.0 s


def test_a_stale_phase_event_is_ignored():
    m = BehaviorMachine(SPECS["face"])
    feed(m, Event(EventKind.TRANSFER_STARTED, 2.0, 2.0))
    feed(m, Event(EventKind.REACH_STARTED, 1.0, 2.1))  # happened before the transfer: stale
    assert m.phase is Phase.TRANSFER and m.ignored == 1


def test_a_missing_transfer_is_skipped_and_the_reach_gaze_carries_on():
    m = BehaviorMachine(SPECS["face-hand-face"])
    feed(m, Event(EventKind.REACH_STARTED, 0.0, 0.0))
    assert m.target(GazeContext(0.8, points(0.8), tracking_end=1.0)).kind == "hand"
    feed(m, Event(EventKind.RETREAT_STARTED, 1.0, 1.0))
    assert m.target(GazeContext(1.1, points(1.1), tracking_end=2.0)).kind == "hand"
    assert m.state == "retreat_hand"


def test_the_machine_reads_its_phase_only_from_the_handover_state():
    # No phase copy to reconcile: a context has no phase, the handover state's is the only one.
    m = BehaviorMachine(SPECS["face-hand-face"])
    assert m.target(GazeContext(2.1, points(2.1), tracking_end=math.nan)).kind == "face"
    assert m.state == "idle_face" and m.phase is m.handover.phase is Phase.IDLE
    m.handover.apply(Event(EventKind.TRANSFER_STARTED, 2.0, 2.0))  # fed behind its back
    assert m.phase is Phase.TRANSFER


def test_a_new_reach_after_a_missed_handover_done_starts_a_new_handover():
    m = BehaviorMachine(SPECS["face-hand-face"])
    for kind, t in (("reach_started", 0.0), ("transfer_started", 1.0), ("retreat_started", 1.5)):
        feed(m, Event(EventKind(kind), t, t))
    feed(m, Event(EventKind.REACH_STARTED, 5.0, 5.0))
    assert m.phase is Phase.REACH
    assert m.target(GazeContext(5.1, points(5.1), tracking_end=6.0)).kind == "face"


def test_garbage_events_are_ignored():
    m = BehaviorMachine(SPECS["hand"])
    feed(m, Event("not-a-kind", 1.0, 1.0))  # type: ignore[arg-type]
    feed(m, Event(EventKind.REACH_STARTED, math.nan, math.nan))
    feed(m, Event(EventKind.ROBOT_REACH_STARTED, 1.0, 1.0, "oops"))  # type: ignore[arg-type]
    # The malformed info is dropped; the robot's reach itself still starts the handover's reach.
    assert m.ignored == 2 and m.state == "reach_hand"


def test_unknown_named_target_falls_back_to_the_last_known_point(tmp_path):
    path = tmp_path / "shelf.yaml"
    path.write_text("segments:\n  - {phase: reach, at: 0.0, target: shelf}\n", encoding="utf-8")
    m = BehaviorMachine(load_behavior(path))
    feed(m, Event(EventKind.REACH_STARTED, 0.0, 0.0))
    pts = points(0.1)
    target = m.target(GazeContext(0.1, pts, tracking_end=1.0))
    assert target.kind == "shelf"
    np.testing.assert_allclose(target.point, pts["face"])
    pts["shelf"] = np.array([0.5, 0.5, 1.2])
    np.testing.assert_allclose(
        m.target(GazeContext(0.2, pts, tracking_end=1.0)).point, pts["shelf"]
    )


def test_robot_events_of_the_previous_handover_do_not_leak_into_the_next():
    m = BehaviorMachine(SPECS["hand-face-as-studied"])
    feed(m, Event(EventKind.REACH_STARTED, 0.0, 0.0))
    feed(m, Event(EventKind.RETREAT_STARTED, 1.0, 1.0))
    feed(m, Event(EventKind.HANDOVER_DONE, 2.0, 2.0))
    feed(m, Event(EventKind.ROBOT_RETREAT_STARTED, 2.5, 2.5))  # late: the old handover's retreat
    feed(m, Event(EventKind.ROBOT_REACH_STARTED, 4.9, 4.9, {"planned_duration": 1.0}))
    feed(m, Event(EventKind.REACH_STARTED, 5.0, 5.0))
    feed(m, Event(EventKind.RETREAT_STARTED, 6.0, 6.0))
    assert m.target(GazeContext(6.1, points(6.1), tracking_end=7.0)).kind == "hand"
