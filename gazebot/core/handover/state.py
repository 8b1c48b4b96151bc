"""The one handover state: the phase the engine reports is the phase the behavior runs.

:class:`HandoverState` merges two evidence streams into one phase stream:

- the **tracking**: the phase detector's events (``reach_started`` ... ``handover_done``; the
  detector's own gripper/load-share evidence arrives as its events with ``source`` ``gripper``
  or ``load_share``);
- the **robot**: its events (``robot_reach_started``, ``robot_grasped``, ``robot_released``, ...).

The rules are the table :data:`RULES`. The phase is the state of a ``transitions`` machine built
from that table (:func:`machine_definition`: one transition per rule and source phase, the rule's
condition a named condition of it), which ``gazebot behaviors show NAME --diagram`` draws:

- **the first reach wins**: a ``robot_reach_started`` in idle/done starts the reach (the robot
  set off first, seed 6.3); the other party's reach start of the same handover only moves the
  reach start to the earlier of the two, and then the reach's source with it. No second reach
  event follows (the phase stream keeps one event per phase, which restarts and recorders
  count on); the commands' ``phase_source`` and ``handover/phase`` say the revised source;
- **grasp and release are transfer evidence**: ``robot_grasped`` starts the transfer (from idle,
  reach or done), ``robot_released`` (robot-to-human) ends it (the retreat starts);
- **stale events**: a phase-changing event older than the last phase change, a duplicate of the
  current phase's event, or one the phase graph does not allow from the current phase is ignored
  (counted in :attr:`HandoverState.ignored`);
- a phase move backwards (``reach_started`` in transfer/retreat: the previous ``handover_done``
  was missed) or from idle/done starts a **new handover**: the robot events of the previous one
  stop counting.

The state is the phase's one owner: the phase detector reads it (:class:`HandoverView`) and
reports what the tracking shows; the engine applies those events and the robot's to it
(:func:`apply_event`, which tells the behavior). Besides the phase, the state keeps what the
behavior's timing reads: the robot events of the current handover (anchors of
``{after: EVENT}`` segments and their ``planned_duration``), and the estimates of the phase's end
(the phase event's ``expected_end``, the robot's motion plan).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from transitions import Machine

from gazebot.core.types import (
    EVENT_OF_PHASE,
    PHASE_OF_EVENT,
    Event,
    EventKind,
    Phase,
    PhaseSource,
    finite_float,
)

_ORDER = {Phase.IDLE: 0, Phase.REACH: 1, Phase.TRANSFER: 2, Phase.RETREAT: 3, Phase.DONE: 4}
_BETWEEN = (Phase.IDLE, Phase.DONE)
# Robot motions whose planned duration estimates the end of a phase.
_ROBOT_MOTION = {
    Phase.REACH: EventKind.ROBOT_REACH_STARTED,
    Phase.RETREAT: EventKind.ROBOT_RETREAT_STARTED,
}
# Phase-event sources the detector reports that are the robot's gripper / load-share sensors.
_GRIPPER_SOURCES = frozenset({"gripper", "load_share"})


@dataclass(frozen=True)
class Rule:
    """One row of the handover state's table.

    ``trigger`` in a phase of ``sources`` moves to ``dest`` (``dest`` equal to the source phase:
    the phase stays and only its start may move earlier), when ``condition`` holds.
    """

    trigger: EventKind
    sources: tuple[Phase, ...]
    dest: Phase | None  # None: stays in the source phase
    condition: str


_NEWER = "not older than the last phase change"
_SAME = "same handover: the reach starts with the first"
#: Every rule of the handover state (its machine, and so the diagram, is built from it).
RULES: tuple[Rule, ...] = (
    Rule(EventKind.REACH_STARTED, (Phase.IDLE, Phase.DONE), Phase.REACH, _NEWER),
    Rule(
        EventKind.REACH_STARTED,
        (Phase.TRANSFER, Phase.RETREAT),
        Phase.REACH,
        _NEWER + " (handover_done was missed: a new handover)",
    ),
    Rule(EventKind.REACH_STARTED, (Phase.REACH,), None, _SAME + " (the robot's started it)"),
    Rule(EventKind.ROBOT_REACH_STARTED, (Phase.IDLE, Phase.DONE), Phase.REACH, _NEWER),
    Rule(EventKind.ROBOT_REACH_STARTED, (Phase.REACH,), None, _SAME + " (the giver's started it)"),
    Rule(
        EventKind.TRANSFER_STARTED, (Phase.IDLE, Phase.REACH, Phase.DONE), Phase.TRANSFER, _NEWER
    ),
    Rule(
        EventKind.ROBOT_GRASPED,
        (Phase.IDLE, Phase.REACH, Phase.DONE),
        Phase.TRANSFER,
        _NEWER + ": the grasp is transfer evidence",
    ),
    Rule(
        EventKind.RETREAT_STARTED,
        (Phase.IDLE, Phase.REACH, Phase.TRANSFER, Phase.DONE),
        Phase.RETREAT,
        _NEWER + " (a missed phase is skipped)",
    ),
    Rule(
        EventKind.ROBOT_RELEASED,
        (Phase.TRANSFER,),
        Phase.RETREAT,
        _NEWER + ": the release ends the transfer",
    ),
    Rule(
        EventKind.HANDOVER_DONE,
        (Phase.REACH, Phase.TRANSFER, Phase.RETREAT),
        Phase.DONE,
        _NEWER,
    ),
)
_PHASE_TRIGGERS = frozenset(rule.trigger for rule in RULES)
_PHASE_OF_STATE = {p.value: p for p in Phase}


@dataclass(frozen=True)
class PhaseChange:
    """The handover state moved to ``phase`` at ``t`` (from ``previous``).

    Attributes:
        phase: The new phase.
        t: Its start (s).
        previous: The phase it left.
        source: What decided it (``tracking``, ``robot``, ``gripper``).
        new_handover: A new handover began (its gaze starts afresh; ``done`` is never one).
        rule: The :class:`Rule` that applied.
    """

    phase: Phase
    t: float
    previous: Phase
    source: PhaseSource
    new_handover: bool
    rule: Rule


def _parse(event: Event) -> tuple[EventKind, float] | None:
    """``(kind, time)`` of an event (its ``t``, else ``detected_at``); ``None`` when the kind is
    unknown or no time is finite."""
    try:
        kind = EventKind(getattr(event, "kind", None))
    except ValueError:
        return None
    for value in (getattr(event, "t", None), getattr(event, "detected_at", None)):
        t = finite_float(value)
        if t is not None:
            return kind, t
    return None


def event_source(event: Event) -> PhaseSource:
    """What an event is evidence from: the robot's gripper (a grasp, a release, or the
    detector's gripper/load-share evidence), the robot's motion, or the tracking."""
    kind = event.kind
    if kind in (EventKind.ROBOT_GRASPED, EventKind.ROBOT_RELEASED):
        return "gripper"
    if kind not in PHASE_OF_EVENT:
        return "robot"
    info = event.info if isinstance(event.info, dict) else {}
    return "gripper" if info.get("source") in _GRIPPER_SOURCES else "tracking"


#: Builds the condition of a rule's transitions: a callable ``(t, event) -> bool`` whose
#: ``__name__`` is the rule's :attr:`Rule.condition` (the label the diagram shows).
ConditionFactory = Callable[[Rule], Callable[[float, Event], bool]]
#: Builds the callback a rule's transition runs once it applies (``(t, event) -> None``).
CallbackFactory = Callable[[Rule], Callable[[float, Event], None]]


def machine_definition(
    condition: ConditionFactory,
    callback: CallbackFactory | None = None,
    rules: tuple[Rule, ...] = RULES,
) -> dict[str, Any]:
    """The ``transitions`` machine of the handover state, built from the rule table: one state
    per phase, one transition per rule and source phase (trigger: the event's kind; ``dest``
    ``None`` for a rule that keeps the phase, an internal transition), in the table's order.

    Args:
        condition: Builds each rule's condition (see :data:`ConditionFactory`).
        callback: Builds what each rule's transition does (its ``before`` callback: the state
            is still the source phase); ``None``: none.
        rules: The table (default :data:`RULES`).

    Returns:
        ``transitions`` keyword arguments: ``states``, ``transitions`` and ``initial``.
    """
    transitions: list[dict[str, Any]] = []
    for rule in rules:
        check = condition(rule)
        run = callback(rule) if callback is not None else None
        for source in rule.sources:
            transition: dict[str, Any] = {
                "trigger": rule.trigger.value,
                "source": source.value,
                "dest": rule.dest.value if rule.dest is not None else None,
                "conditions": [check],
            }
            if run is not None:
                transition["before"] = [run]
            transitions.append(transition)
    return {
        "states": [p.value for p in Phase],
        "transitions": transitions,
        "initial": Phase.IDLE.value,
    }


class HandoverView(Protocol):
    """What the phase detector reads of the handover state (read-only; a
    :class:`HandoverState` is one)."""

    @property
    def phase(self) -> Phase:
        """The current phase."""
        ...

    @property
    def phase_start(self) -> float:
        """Its start (s; -inf before any handover)."""
        ...

    @property
    def handover(self) -> int:
        """Index of the current (or last) handover, -1 before the first."""
        ...

    @property
    def handover_t0(self) -> float:
        """Events at or after this belong to the current handover (s): the previous
        handover's end, -inf for the first."""
        ...

    @property
    def reach_tracked(self) -> bool:
        """The tracking reported the current handover's reach start (False while a reach
        only the robot started waits for the giver's: the first reach wins)."""
        ...

    @property
    def entry(self) -> int:
        """Grows whenever the phase the tracking follows is entered or its start moves (a
        reach only the robot started is not one until the giver's joins it)."""
        ...


class PhaseFollower(Protocol):
    """What reacts to the handover state's changes (the behavior machine)."""

    def advance(self, t: float) -> None:
        """Bring everything due by ``t`` up to date (before a phase change at ``t``)."""

    def on_phase(self, change: PhaseChange) -> None:
        """The state changed phase."""

    def on_tracking(self, event: Event) -> None:
        """``tracking_lost`` / ``tracking_restored``."""


def apply_event(state: HandoverState, follower: PhaseFollower, event: Event) -> PhaseChange | None:
    """Apply one event to ``state`` and tell ``follower``: tracking events go to it alone; a
    phase or robot event that moves the phase first lets it catch up to the event's time
    (what is due by then is the gaze that carries on), then tells it the change. Returns the
    change, else ``None``."""
    kind = getattr(event, "kind", None)
    if kind is EventKind.TRACKING_LOST or kind is EventKind.TRACKING_RESTORED:
        follower.on_tracking(event)
        return None
    t = state.would_move(event)
    if t is not None:
        follower.advance(t)
    change = state.apply(event)
    if change is not None:
        follower.on_phase(change)
    return change


class _Model:
    """The object whose ``state`` (a phase's value) the handover machine drives."""

    state: str
    trigger: Callable[..., bool]  # added by the machine: fires a trigger, True if it moved


class HandoverState:
    """The current handover's phase and the evidence its timing reads (see the module docs).

    The phase is the state of a ``transitions`` machine built from :data:`RULES`
    (:func:`machine_definition`; :attr:`definition` is what it was built from, with the
    conditions and callbacks that run). Feed every phase and robot event with :meth:`apply`
    (phase changes come back); read :attr:`phase`, :attr:`phase_start` and :attr:`source`.
    """

    def __init__(self) -> None:
        self._model = _Model()
        # Each rule's condition, built once: the machine runs them, would_move asks them.
        self._checks = {rule: self._condition(rule) for rule in RULES}
        #: The machine's definition (``transitions`` keyword arguments), live callables included.
        self.definition = machine_definition(self._checks.__getitem__, self._callback)
        self._machine = Machine(
            model=self._model,
            **self.definition,
            auto_transitions=False,
            ignore_invalid_triggers=True,
        )
        #: Counts every change of what the behavior's timing reads (phase, its start, robot
        #: events); never goes back, not even on :meth:`reset`.
        self.revision = 0
        #: Counts the entries of the phase the tracking follows (see :class:`HandoverView`);
        #: never goes back, not even on :meth:`reset`.
        self.entry = 0
        self.reset()

    def reset(self) -> None:
        """Back to idle before any handover (the machine is kept: building one costs more)."""
        self._machine.set_state(Phase.IDLE.value, self._model)
        self.phase_start = -math.inf
        self.source: PhaseSource = "tracking"
        #: Index of the current (or last) handover, -1 before the first.
        self.handover = -1
        #: Events ignored as stale, duplicated or not allowed from the current phase.
        self.ignored = 0
        #: The phase event's own ``expected_end`` (s), NaN when it gave none.
        self.event_end = math.nan
        #: Events at or after this belong to the current handover (s).
        self.handover_t0 = -math.inf
        self._last_change = -math.inf
        self._reach_by: set[str] = set()  # "robot" / "giver": who started the reach
        self._robot: dict[EventKind, Event] = {}
        self._change: PhaseChange | None = None
        self.revision += 1
        self.entry += 1

    @property
    def phase(self) -> Phase:
        """The current phase (the machine's state)."""
        return _PHASE_OF_STATE[self._model.state]

    @property
    def reach_tracked(self) -> bool:
        """The tracking reported the current handover's reach start."""
        return "giver" in self._reach_by

    # ----------------------------------------------------------------- input
    def apply(self, event: Event) -> PhaseChange | None:
        """Apply one phase or robot event; the phase change it caused, else ``None``.

        Events with an unknown kind or no finite time are ignored (counted); tracking events
        are not the handover state's (returns ``None`` without counting). A phase-changing
        event no rule of the current phase accepts (stale, duplicate, not allowed) is ignored
        and counted.
        """
        parsed = _parse(event)
        if parsed is None:
            self.ignored += 1
            return None
        kind, t = parsed
        if kind not in PHASE_OF_EVENT and kind.value.startswith("robot_"):
            if not self._keep_robot(kind, t, event):
                self.ignored += 1
                return None
        if kind not in _PHASE_TRIGGERS:
            return None
        self._change = None
        if not self._model.trigger(kind.value, t, event):
            if kind in PHASE_OF_EVENT:  # stale, duplicate or not allowed from this phase
                self.ignored += 1
            return None
        change, self._change = self._change, None
        return change

    def would_move(self, event: Event) -> float | None:
        """The time (s) at which ``event`` would change the phase, ``None`` if it would not
        (nothing changes: the behavior first brings its gaze up to that time). Asks the
        rule table, whose conditions the machine runs."""
        parsed = _parse(event)
        if parsed is None or parsed[0] not in _PHASE_TRIGGERS:
            return None
        kind, t = parsed
        phase = self.phase
        for rule in RULES:  # (the machine's transitions, in its order)
            if rule.trigger is kind and phase in rule.sources and self._checks[rule](t, event):
                return t if rule.dest is not None else None
        return None

    # ----------------------------------------------------------------- the machine's rules
    def _condition(self, rule: Rule) -> Callable[[float, Event], bool]:
        """The runtime condition of ``rule``'s transitions (named with its label)."""
        if rule.dest is not None:

            def condition(t: float, event: Event) -> bool:
                return t >= self._last_change  # a stale event does not move the phase

        else:

            party = "robot" if rule.trigger is EventKind.ROBOT_REACH_STARTED else "giver"
            phase_event = rule.trigger in PHASE_OF_EVENT

            def condition(t: float, event: Event) -> bool:
                # The other party's reach start of this handover (a duplicate of the same
                # party's phase event is not: it is ignored).
                duplicate = phase_event and party in self._reach_by
                return t >= self.handover_t0 and not duplicate

        condition.__name__ = rule.condition
        return condition

    def _callback(self, rule: Rule) -> Callable[[float, Event], None]:
        """What ``rule``'s transition does: enter its phase, or join the reach."""
        if rule.dest is not None:

            def callback(t: float, event: Event) -> None:
                self._change = self._enter(rule, t, event)

            callback.__name__ = f"enter {rule.dest.value}"
        else:

            def callback(t: float, event: Event) -> None:
                self._earlier_reach(rule.trigger, t, event)

            callback.__name__ = "join the reach"
        return callback

    # ----------------------------------------------------------------- timing evidence
    def anchor(self, kind: EventKind) -> float:
        """When ``kind`` happened in the current handover (s): the phase's start for the event
        that started the current phase, else the robot's latest such event; NaN if not yet."""
        if EVENT_OF_PHASE.get(self.phase) is kind:
            return self.phase_start
        ev = self._robot.get(kind)
        if ev is None or ev.t < self.handover_t0:
            return math.nan
        return ev.t

    def robot_motion_end(self) -> float:
        """End of the robot's own reach/retreat in the current phase (start + planned
        duration, s), NaN if unknown."""
        motion = _ROBOT_MOTION.get(self.phase)
        ev = self._robot.get(motion) if motion is not None else None
        if ev is None or ev.t < self.handover_t0:
            return math.nan
        planned = finite_float(ev.info.get("planned_duration"))
        return ev.t + planned if planned is not None and planned > 0 else math.nan

    # ----------------------------------------------------------------- internals
    def _keep_robot(self, kind: EventKind, t: float, event: Event) -> bool:
        old = self._robot.get(kind)
        if old is not None and old.t > t:
            return False  # an older copy arriving late
        info: Any = getattr(event, "info", None)
        self._robot[kind] = Event(kind, t, t, dict(info) if isinstance(info, dict) else {})
        self.revision += 1
        return True

    def _earlier_reach(self, kind: EventKind, t: float, event: Event) -> None:
        """The other party's reach start of the current handover: the reach starts with the
        first. An earlier start also takes over the phase's source: the reach is the earlier
        party's, whichever was told first."""
        by_robot = kind is EventKind.ROBOT_REACH_STARTED
        self._reach_by.add("robot" if by_robot else "giver")
        moved = t < self.phase_start
        if moved:
            self.phase_start = t
            self.source = event_source(event)
            self.revision += 1
        if moved or not by_robot:  # the tracking follows the reach from now on
            self.entry += 1

    def _enter(self, rule: Rule, t: float, event: Event) -> PhaseChange:
        """Enter ``rule.dest`` at ``t`` (called before the machine moves: :attr:`phase` is
        still the one left)."""
        previous, phase = self.phase, rule.dest
        assert phase is not None
        new = phase is not Phase.DONE and (
            previous in _BETWEEN or _ORDER[phase] <= _ORDER[previous]
        )
        if new:
            # Keep only what belongs to this handover: events since its start, and a robot
            # reach that began between the previous handover's end and this start.
            if previous is Phase.DONE:
                self.handover_t0 = self.phase_start
            elif previous is not Phase.IDLE:
                self.handover_t0 = t  # the previous handover_done was missed
            self._robot = {
                k: e
                for k, e in self._robot.items()
                if e.t >= t or (k is EventKind.ROBOT_REACH_STARTED and e.t >= self.handover_t0)
            }
            self.handover += 1
            self._reach_by = set()
        by_robot = rule.trigger is EventKind.ROBOT_REACH_STARTED
        if phase is Phase.REACH:
            self._reach_by.add("robot" if by_robot else "giver")
        if not by_robot:  # (a reach only the robot started is none the tracking follows yet)
            self.entry += 1
        self.phase_start = t
        self._last_change = t
        self.source = event_source(event)
        info = event.info if isinstance(event.info, dict) else {}
        expected = info.get("expected_end", math.nan)
        end = finite_float(expected)
        self.event_end = end if end is not None else math.nan
        self.revision += 1
        return PhaseChange(phase, t, previous, self.source, new, rule)
