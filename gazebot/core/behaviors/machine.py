"""The behavior state machine: the ``transitions`` machine's states are the gaze decisions.

The machine keeps **no phase of its own**: it reads the one
:class:`~gazebot.core.handover.HandoverState` (the engine's, or its own when run alone) and reacts
to its phase changes and to the tick; it never passes events on to the state (whoever applies
them, the engine, tells it: :func:`gazebot.core.handover.apply_event`).
:func:`machine_definition` builds one ``transitions`` hierarchical machine
with two parallel regions under the root state ``behavior``; every rule that decides the gaze
target is one of its transitions, with a named condition, and runs in it:

- ``gaze``: one state per gaze target (``behavior_gaze_face``, ``behavior_gaze_hand``, ...).
  Its transitions:

  * ``phase`` (the handover state changed phase; the trigger carries the
    :class:`~gazebot.core.handover.PhaseChange`) ``[new handover]`` -> the behavior's ``before``
    target (the reach of a new handover starts afresh; a data-driven behavior draws its
    segments), ``[handover done]`` -> its ``after`` target, ``[same handover: the gaze
    carries]`` (internal: reach -> transfer -> retreat keep the target they had); each then
    enters the new phase's segments (its ``after`` callbacks);
  * ``timer`` (the trigger carries the :class:`Tick`: the time and the tracking's end estimate)
    ``[PHASE: WHEN (RULE)]`` -> a segment's target, once per segment of the behavior:
    ``0.5 of the reach (end: latest of tracking, event, robot plan; else 1.01 s)`` or
    ``robot_reach_ended + 0.2 s``. Their ``prepare`` callback schedules the phase at the tick
    with the pure :func:`gazebot.core.behaviors.schedule.schedule` (the expected end, each
    segment's start, the due ones); the condition holds for the segment the gaze follows:
    when several start by the same tick the latest start wins. ``timer [due, but before the
    followed segment's start ...]`` (internal) starts segments that do not take the gaze
    back. Their ``after`` callbacks mark the due segments started and record the origin.

- ``tracking``: ``ok`` -> ``hold`` on ``tracking_lost`` (the gaze point is held), ``hold`` ->
  ``lost`` on ``timer [held HOLD s]`` (:func:`~gazebot.core.behaviors.schedule.hold_over`; then the
  policy's target, by default the last known face), back to ``ok`` on ``tracking_restored
  [after the loss]`` (an older restore is stale). Phases and gaze shifts keep advancing
  meanwhile, so on restore the gaze resumes where the behavior now is.

:meth:`BehaviorMachine.advance` only feeds the tick; it skips the ``timer`` trigger when the
machine could not fire anything: before the hold's end and before the earliest start its last
schedule found (:attr:`~gazebot.core.behaviors.schedule.Schedule.wake`) while that schedule's
evidence is unchanged (the handover state's ``revision``; the end estimate when a waiting start
depends on it). A machine fed every tick decides the same (a property test).

``gazebot behaviors show NAME --diagram FILE`` draws this machine, with the handover state's own
machine (built from its rule table :data:`gazebot.core.handover.RULES`: first reach wins,
grasp/release, stale events) as a third region, from the definitions a :class:`BehaviorMachine`
runs on, live conditions included (:func:`diagram`).

:meth:`BehaviorMachine.state` reads e.g. ``reach_hand`` (the handover state's phase, the gaze
state, and ``_hold``/``_lost`` while tracking is lost). :attr:`BehaviorMachine.origin`
(:class:`GazeOrigin`) names the rule that picked the current gaze state and the phase of that
rule, recorded when it picked it; a gaze carried into a later phase unchanged keeps that phase
and says which phase it was carried into.

Fraction timings need the phase's end online: :func:`gazebot.core.behaviors.schedule.expected_end`
combines the tracking's prediction (``GazeContext.tracking_end``), the phase event's
``expected_end`` and the robot's motion plan, else the spec's ``phase_durations_s``. Each
schedule re-reads them; a segment that has started stays started, so a revised estimate never
moves the gaze back.

Points: the returned point is ``ctx.points[kind]`` (the hand moves: it is read every call). When
that point is missing (NaN or an unknown named point) the last finite position of that kind is
used, then its default (``defaults``: e.g. the robot's ``handover_location`` for the hand), else
the face, then ``rest``; the point is NaN only if none was ever known. This is the engine's one
memory of last known points.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from transitions.extensions import HierarchicalMachine

from gazebot.core.behaviors.schedule import Schedule, end_rule, hold_over, schedule
from gazebot.core.behaviors.spec import (
    SEGMENT_PHASES,
    AtEvent,
    AtFraction,
    AtNever,
    BehaviorSpec,
    Segment,
)
from gazebot.core.handover import HandoverState, PhaseChange
from gazebot.core.types import (
    Event,
    EventKind,
    GazeContext,
    GazeTarget,
    Phase,
    TrackingState,
    finite_float,
)

_ROOT, _GAZE, _TRACKING = "behavior", "behavior_gaze", "behavior_tracking"
_TRACKING_STATES: tuple[TrackingState, ...] = ("ok", "hold", "lost")
_TRACKING_OK, _TRACKING_HOLD = f"{_TRACKING}_ok", f"{_TRACKING}_hold"
_NEW, _DONE, _CARRY = "new handover", "handover done", "same handover: the gaze carries"
_RESTORED = "after the loss"
_STAYS = "due, but before the followed segment's start: the latest start wins, the gaze stays"




def _state_name(target: str) -> str:
    # ``_`` separates nested state names in ``transitions``: ``handover_location`` is a target,
    # not a state ``location`` inside ``handover``.
    return target.replace("_", "-")


def _gaze_targets(spec: BehaviorSpec) -> list[str]:
    """The targets the ``gaze`` region can be in: ``before`` first, then sorted."""
    names = {spec.before, spec.after, *(s.target for s in spec.segments)}
    if spec.human is not None:
        names |= spec.human.targets()
    ordered = [spec.before, *sorted(names - {spec.before})]
    states = [_state_name(n) for n in ordered]
    if len(set(states)) != len(states):
        raise ValueError(f"behavior '{spec.name}': targets differing only in '_' vs '-'")
    return ordered


def _describe(spec: BehaviorSpec, at: AtFraction | AtEvent, phase: Phase) -> str:
    if isinstance(at, AtFraction):
        if at.fraction == 0:
            return f"at the {phase.value}'s start"
        default = spec.phase_durations_s.of(phase)
        return f"{at.fraction:g} of the {phase.value} ({end_rule(phase, default)})"
    return at.after.value + (f" + {at.delay:g} s" if at.delay else "")


def _slots(spec: BehaviorSpec) -> dict[Phase, list[tuple[int, str, str]]]:
    """Per phase, every ``(segment index, target, label)`` that can start in a handover
    (``never`` segments cannot)."""
    out: dict[Phase, list[tuple[int, str, str]]] = {p: [] for p in SEGMENT_PHASES}
    if spec.human is not None:
        for phase in SEGMENT_PHASES:
            seen = set()
            default = spec.phase_durations_s.of(phase)
            for pattern in spec.human.patterns:
                for i, target in enumerate(getattr(pattern, phase.value)):
                    if (i, target) not in seen:
                        seen.add((i, target))
                        when = (
                            "start" if i == 0
                            else f"drawn fraction {i} ({end_rule(phase, default)})"
                        )
                        out[phase].append((i, target, when))
        return out
    for phase in SEGMENT_PHASES:
        segs = [s for s in spec.segments if s.phase == phase.value]
        for i, seg in enumerate(segs):
            at = spec.resolve(seg)
            if not isinstance(at, AtNever):
                out[phase].append((i, seg.target, _describe(spec, at, phase)))
    return out


_PHASE_ORDER = {p: i for i, p in enumerate(Phase)}


@dataclass(frozen=True)
class GazeOrigin:
    """The rule that picked the gaze region's current state, recorded when it picked it.

    Attributes:
        phase: The phase of the rule: a segment's own phase, or the phase a new handover
            (``before``) or the end (``after``) was entered with.
        rule: ``before``, ``after`` or ``segment N`` (N: its index in that phase's segments).
        target: The target kind the rule picked.
        t: When it picked it (s; NaN before any).
        carried_into: The phase the gaze has since been carried into unchanged (a phase change
            that is no new handover keeps the gaze); ``None`` while the rule's phase is current.
    """

    phase: Phase
    rule: str
    target: str
    t: float = math.nan
    carried_into: Phase | None = None

    def disagreement(self, phase: Phase, target: str) -> str | None:
        """Why a command reporting ``phase`` and ``target`` (tracking ok) disagrees with this
        origin: the target is not the one the rule picked, a phase's own rule is not the
        reported phase's, or a carried gaze was carried into another phase (or backwards);
        ``None`` when they agree."""
        if target != self.target:
            return (f"target {target!r}, but {self.rule} of {self.phase.value} picked "
                    f"{self.target!r}")
        if self.carried_into is None:
            if self.phase is not phase:
                return (f"reported {phase.value}, but the target is {self.rule} of "
                        f"{self.phase.value}")
            return None
        if self.carried_into is not phase:
            return (f"reported {phase.value}, but the gaze was carried into "
                    f"{self.carried_into.value}")
        if _PHASE_ORDER[self.phase] >= _PHASE_ORDER[phase]:
            return f"gaze carried from {self.phase.value} back into {phase.value}"
        return None


@dataclass(frozen=True)
class Tick:
    """What the ``timer`` trigger carries: the time (s) and the tracking's latest prediction of
    the phase's end (s, NaN if none)."""

    t: float
    tracking_end: float


#: Builds a transition condition from its key and label: ``("segment", phase, index, target)``,
#: ``("phase", name)``, ``("stays",)``, ``("held",)`` or ``("restored",)``. The callable takes
#: the trigger's argument (a :class:`Tick`, a :class:`PhaseChange` or an event's time) and its
#: ``__name__`` is the label the diagram shows.
ConditionFactory = Callable[[tuple, str], Callable[[Any], bool]]
#: Builds a transition's callbacks from its key: ``{"prepare": [...], "after": [...]}`` (or
#: nothing); each callable takes the trigger's argument.
CallbackFactory = Callable[[tuple], dict[str, list[Callable[[Any], None]]]]


def machine_definition(
    spec: BehaviorSpec,
    condition: ConditionFactory,
    callbacks: CallbackFactory | None = None,
) -> dict[str, Any]:
    """The states, transitions and initial state of ``spec``'s machine (``transitions``
    keyword arguments).

    Args:
        spec: The behavior.
        condition: Builds each transition's condition (see :data:`ConditionFactory`).
        callbacks: Builds each transition's ``prepare``/``after`` callbacks, by the same keys
            (see :data:`CallbackFactory`; the tracking-loss transition's key is ``("lost",)``);
            ``None``: none.
    """
    gaze = [_state_name(t) for t in _gaze_targets(spec)]
    before, after = _state_name(spec.before), _state_name(spec.after)
    states = [
        {
            "name": _ROOT,
            "parallel": [
                {"name": "gaze", "children": gaze, "initial": before},
                {"name": "tracking", "children": list(_TRACKING_STATES), "initial": "ok"},
            ],
        }
    ]

    def leaf(name: str) -> str:
        return f"{_GAZE}_{name}"

    def transition(
        trigger: str, source: Any, dest: str | None, key: tuple, label: str | None
    ) -> dict[str, Any]:
        out: dict[str, Any] = {"trigger": trigger, "source": source, "dest": dest}
        if label is not None:
            out["conditions"] = [condition(key, label)]
        if callbacks is not None:
            out.update(callbacks(key))
        return out

    transitions: list[dict[str, Any]] = [
        transition("phase", _GAZE, leaf(before), ("phase", _NEW), _NEW),
        transition("phase", _GAZE, leaf(after), ("phase", _DONE), _DONE),
        # internal: the gaze state stays
        transition("phase", _GAZE, None, ("phase", _CARRY), _CARRY),
    ]
    slots = _slots(spec)
    for phase, phase_slots in slots.items():
        for index, target, when in phase_slots:
            transitions.append(
                transition(
                    "timer",
                    _GAZE,
                    leaf(_state_name(target)),
                    ("segment", phase, index, target),
                    f"{phase.value}: {when}",
                )
            )
    if any(slots.values()):
        transitions.append(transition("timer", _GAZE, None, ("stays",), _STAYS))
    hold = f"held {spec.tracking_lost.hold_s:g} s"
    transitions += [
        transition(
            EventKind.TRACKING_LOST.value, _TRACKING_OK, _TRACKING_HOLD, ("lost",), None
        ),
        transition("timer", _TRACKING_HOLD, f"{_TRACKING}_lost", ("held",), hold),
        transition(
            EventKind.TRACKING_RESTORED.value,
            [_TRACKING_HOLD, f"{_TRACKING}_lost"],
            _TRACKING_OK,
            ("restored",),
            _RESTORED,
        ),
    ]
    return {"states": states, "transitions": transitions, "initial": _ROOT}


def _nested(definition: dict[str, Any], region: str) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """A flat machine's definition (states named by strings) as the region ``region`` of the
    root state: the region's state and its transitions with the nested state names."""

    def name(state: str | None) -> str | None:
        return None if state is None else f"{_ROOT}_{region}_{state}"

    state = {
        "name": region,
        "children": list(definition["states"]),
        "initial": definition["initial"],
    }
    transitions = [
        {**t, "source": name(t["source"]), "dest": name(t["dest"])}
        for t in definition["transitions"]
    ]
    return state, transitions


def diagram(spec: BehaviorSpec) -> str:
    """The machine of ``spec`` as Mermaid ``stateDiagram-v2`` text, drawn by ``transitions``' own
    diagram support (``HierarchicalGraphMachine`` with ``graph_engine="mermaid"``) from the
    definitions a :class:`BehaviorMachine` of ``spec`` runs on, live conditions included: its
    own (``gaze`` and ``tracking``) and its handover state's (:attr:`HandoverState.definition`,
    built from :data:`gazebot.core.handover.RULES`), drawn as the region ``handover``."""
    from transitions.extensions import HierarchicalGraphMachine

    class Drawn:
        """A model for the drawing only (never triggered)."""

    running = BehaviorMachine(spec)
    definition = dict(running.definition)
    root = dict(definition["states"][0])
    region, rules = _nested(running.handover.definition, "handover")
    root["parallel"] = [region, *root["parallel"]]
    definition["states"] = [root]
    definition["transitions"] = rules + list(definition["transitions"])
    model = Drawn()
    HierarchicalGraphMachine(
        model=model,
        **definition,
        auto_transitions=False,
        graph_engine="mermaid",
        show_conditions=True,
        title=f"gaze behavior {spec.name}",
    )
    text = str(model.get_graph().draw(None))  # type: ignore[attr-defined]
    return "\n".join(_without_empty_labels(line) for line in text.split("\n"))


def _without_empty_labels(line: str) -> str:
    """``line`` without the empty alternatives in its edge label: ``transitions`` draws a
    region's initial state as an unlabelled edge from the region, and when a labelled edge joins
    the same two states it adds ``" | "`` plus nothing (the initial state is drawn as ``[*]``
    inside the region anyway)."""
    head, sep, label = line.partition(": ")
    if not sep or "-->" not in head:
        return line
    return head + sep + " | ".join(part for part in label.split(" | ") if part.strip())


class _Model:
    """The object whose ``state`` the ``transitions`` machine drives."""

    state: list[str]
    trigger: Callable[..., bool]  # added by the machine: fires a trigger, True if it moved


class BehaviorMachine:
    """Runs a :class:`BehaviorSpec`: it follows its handover state (phase changes through
    :meth:`on_phase`, tracking events through :meth:`on_tracking`: whoever applies events to
    the state tells it, see :func:`gazebot.core.handover.apply_event`) and is asked
    :meth:`target` each tick.

    Args:
        spec: The behavior.
        seed: Seed for behaviors that draw timings (``human-receiver``); equal seeds and equal
            inputs give equal outputs.
        handover: The handover state to read the phase from (the engine's); ``None``: one of its
            own (:attr:`handover`, fed with :func:`~gazebot.core.handover.apply_event`).
        defaults: Fallback positions (base frame, m) per target kind, for a kind never seen yet
            (the engine's: the robot's default face, its ``handover_location`` for the hand).
    """

    # The memory of the current handover (set by reset()).
    _plan: dict[Phase, list[Segment]]  # its segments per phase
    _segments: list[Segment]  # the current phase's
    _timings: list[AtFraction | AtEvent | AtNever]  # ... and when each starts
    _started: list[bool]
    _latest: float  # start time of the segment the gaze state follows
    _scheduled: Tick | None  # the tick the last schedule was made for
    _wake_revision: int | None  # the evidence wake holds for; None: any
    _wake_end: float | None
    # The last (kind, point) aimed at with tracking ok, and the one held while lost.
    _held: tuple[str, np.ndarray] | None
    _last_target: tuple[str, np.ndarray] | None
    _known: dict[str, np.ndarray]  # the last valid point of each kind

    def __init__(
        self,
        spec: BehaviorSpec,
        seed: int = 0,
        handover: HandoverState | None = None,
        defaults: Mapping[str, np.ndarray] | None = None,
    ) -> None:
        self.spec = spec
        self._owns_handover = handover is None
        self.handover = handover if handover is not None else HandoverState()
        self._defaults = {k: np.asarray(v, float) for k, v in (defaults or {}).items()}
        self._target_of = {_state_name(t): t for t in _gaze_targets(spec)}
        self._model = _Model()
        #: The machine's definition (``transitions`` keyword arguments) with the conditions and
        #: callbacks that run; :func:`diagram` draws it.
        self.definition = machine_definition(spec, self._condition, self._callbacks)
        self._machine = HierarchicalMachine(
            model=self._model,
            **self.definition,
            auto_transitions=False,
            ignore_invalid_triggers=True,
        )
        self._gaze_leaf = {f"{_GAZE}_{s}": s for s in self._target_of}
        self._tracking_leaf = {f"{_TRACKING}_{s}": s for s in _TRACKING_STATES}
        # Per-tick lookups done once (the spec is frozen): the gaze target of each gaze-region
        # state, and the target while tracking is lost.
        self._kind_of_state = {leaf: self._target_of[s] for leaf, s in self._gaze_leaf.items()}
        self._lost_kind = spec.tracking_lost.target
        self.reset(seed)

    # ----------------------------------------------------------------- the machine's rules
    def _condition(self, key: tuple, label: str) -> Callable[[Any], bool]:
        """The runtime condition of a transition (see :data:`ConditionFactory`)."""
        kind = key[0]
        condition: Callable[[Any], bool]
        if kind == "segment":
            _, phase, index, target = key

            def follows(tick: Tick) -> bool:
                # The segment the gaze follows now (the tick's schedule: the latest due start),
                # with this target (the drawn pattern's).
                return (
                    self._schedule.follow == index
                    and self.handover.phase is phase
                    and self._segments[index].target == target
                )

            condition = follows
        elif kind == "stays":

            def stays(tick: Tick) -> bool:
                return bool(self._schedule.fired) and self._schedule.follow is None

            condition = stays
        elif kind == "phase":
            rule = key[1]

            def moves(change: PhaseChange) -> bool:
                if rule == _DONE:
                    return change.phase is Phase.DONE
                return change.new_handover is (rule == _NEW) and change.phase is not Phase.DONE

            condition = moves
        elif kind == "held":
            hold_s = self.spec.tracking_lost.hold_s

            def held(tick: Tick) -> bool:
                return hold_over(self._lost_since, hold_s, tick.t)

            condition = held
        else:  # restored

            def restored(t: float) -> bool:
                return t >= self._lost_since  # an older restore is stale

            condition = restored
        condition.__name__ = label
        return condition

    def _callbacks(self, key: tuple) -> dict[str, list[Callable[[Any], None]]]:
        """A transition's ``prepare``/``after`` callbacks (see :data:`CallbackFactory`)."""
        kind = key[0]
        if kind == "segment":
            return {
                "prepare": [self._plan_tick],
                "after": [self._start_due, self._picked_by(key[1], key[2])],
            }
        if kind == "stays":
            return {"prepare": [self._plan_tick], "after": [self._start_due]}
        if kind == "phase":
            first = {_NEW: self._begin, _DONE: self._finish, _CARRY: self._carry}[key[1]]
            return {"after": [first, self._enter_phase]}
        if kind == "lost":
            return {"after": [self._hold]}
        if kind in ("held", "restored"):
            return {"after": [self._end_hold]}
        return {}

    def _plan_tick(self, tick: Tick) -> None:
        """``prepare`` of the gaze's ``timer`` transitions: the current phase's
        :func:`~gazebot.core.behaviors.schedule.schedule` at this tick (once per tick), and when the
        next ``timer`` can start a segment with the same evidence."""
        if self._scheduled is tick:
            return
        self._scheduled = tick
        state = self.handover
        phase = state.phase
        timings = self._timings
        anchors = [
            state.anchor(at.after) if isinstance(at, AtEvent) else math.nan for at in timings
        ]
        plan = schedule(
            timings,
            self._started,
            phase,
            state.phase_start,
            (tick.tracking_end, state.event_end, state.robot_motion_end()),
            self.spec.phase_durations_s.of(phase),
            anchors,
            tick.t,
            self._latest,
        )
        self._schedule = plan
        # Nothing can start before ``wake`` unless the evidence changes (the handover state's
        # revision; the tracking's end estimate when a waiting start depends on it).
        self._wake = plan.wake
        self._wake_revision = state.revision if plan.waiting else None
        self._wake_end = tick.tracking_end if plan.needs_end else None

    def _start_due(self, tick: Tick) -> None:
        """``after`` of the gaze's ``timer`` transitions: the due segments have started (a
        started segment stays started: a revised estimate never moves the gaze back)."""
        plan = self._schedule
        for i in plan.fired:
            self._started[i] = True
        if plan.follow is not None:
            self._latest = plan.starts[plan.follow]

    def _picked_by(self, phase: Phase, index: int) -> Callable[[Tick], None]:
        def picked(tick: Tick) -> None:
            self.origin = GazeOrigin(phase, f"segment {index}", self.gaze, tick.t)

        return picked

    def _begin(self, change: PhaseChange) -> None:
        """A new handover: its segments (drawn anew for a data-driven behavior)."""
        self._plan = self._draw_plan()
        self.origin = GazeOrigin(change.phase, "before", self.gaze, change.t)

    def _finish(self, change: PhaseChange) -> None:
        self.origin = GazeOrigin(change.phase, "after", self.gaze, change.t)

    def _carry(self, change: PhaseChange) -> None:
        # The gaze state stays: its rule is still the earlier phase's.
        self.origin = replace(self.origin, carried_into=change.phase)

    def _enter_phase(self, change: PhaseChange) -> None:
        """The phase's segments, none started yet."""
        phase = change.phase
        self._segments = self._plan.get(phase, [])
        self._timings = [self.spec.resolve(s) for s in self._segments]
        self._started = [False] * len(self._segments)
        self._latest = -math.inf
        self._tracking_end = math.nan
        # The next tick schedules the phase, unless no segment of it can ever start.
        can_start = any(not isinstance(at, AtNever) for at in self._timings)
        self._wake = -math.inf if can_start else math.inf
        self._wake_revision = None
        self._wake_end = None

    def _hold(self, t: float) -> None:
        """Tracking lost at ``t``: hold the gaze point until the hold is over."""
        self._lost_since = t
        self._held = self._last_target
        self._hold_until = t + self.spec.tracking_lost.hold_s

    def _end_hold(self, arg: Any) -> None:
        self._hold_until = math.inf

    # ----------------------------------------------------------------- state
    def reset(self, seed: int | None = None) -> None:
        """Forget everything (back to ``idle``; a machine with its own handover state resets
        it too), optionally with a new seed (building a new machine takes milliseconds)."""
        if seed is not None:
            self.seed = int(seed)
        if self._owns_handover:
            self.handover.reset()
        self._ignored = 0  # tracking events ignored as stale or duplicated
        self.pattern = ""  # name of the drawn pattern (data-driven behaviors)
        self._rng = np.random.default_rng(self.seed)
        self._plan = self._draw_plan()
        self._segments = []
        self._timings = []
        self._started = []
        self._latest = -math.inf
        self._schedule = Schedule((), (), None, math.inf, False, False)
        self._scheduled = None
        self._wake = math.inf
        self._wake_revision = None
        self._wake_end = None
        self._tracking_end = math.nan
        self._lost_since = math.nan
        self._hold_until = math.inf
        self._held = None
        self._last_target = None
        self._known = {}
        self._machine.set_state([f"{_GAZE}_{_state_name(self.spec.before)}", _TRACKING_OK])
        self.origin = GazeOrigin(Phase.IDLE, "before", self.gaze)

    def _draw_plan(self) -> dict[Phase, list[Segment]]:
        """The segments of the next handover (drawn from the data model for ``human``)."""
        if self.spec.human is not None:
            self.pattern, segments = self.spec.human.sample(self._rng)
        else:
            segments = list(self.spec.segments)
        return {p: [s for s in segments if s.phase == p.value] for p in SEGMENT_PHASES}

    # ----------------------------------------------------------------- public API
    @property
    def state(self) -> str:
        """Current state, e.g. ``idle_face``, ``reach_hand``, ``retreat_face_lost`` (the handover
        state's phase, the gaze target's state and, while tracking is lost, ``hold`` or
        ``lost``)."""
        gaze, tracking = self._model.state
        name = f"{self.handover.phase.value}_{self._gaze_leaf[gaze]}"
        tracking = self._tracking_leaf[tracking]
        return name if tracking == "ok" else f"{name}_{tracking}"

    @property
    def states(self) -> list[str]:
        """Every value :attr:`state` can take."""
        before, after = _state_name(self.spec.before), _state_name(self.spec.after)
        combos = [("idle", before), ("done", after)]
        combos += [(p.value, g) for p in SEGMENT_PHASES for g in self._target_of]
        return [f"{p}_{g}{s}" for p, g in combos for s in ("", "_hold", "_lost")]

    def origin_disagreement(self, phase: Phase, target: str) -> str | None:
        """Why a command reporting ``phase`` and ``target`` now (tracking ok) disagrees with the
        rule that picked the gaze (:meth:`GazeOrigin.disagreement`, and a ``segment N`` origin
        must be segment N of its phase's plan, with that target); ``None`` when it agrees."""
        origin = self.origin
        why = origin.disagreement(phase, target)
        if why is None and origin.rule.startswith("segment "):
            plan = self._plan.get(origin.phase, [])
            index = int(origin.rule.split()[1])
            if index >= len(plan) or plan[index].target != origin.target:
                why = f"{origin.phase.value} has no {origin.rule} looking at {origin.target!r}"
        return why

    @property
    def ignored(self) -> int:
        """Events ignored as stale, duplicated, malformed or not allowed from the phase (the
        handover state's and the tracking region's)."""
        return self._ignored + self.handover.ignored

    @property
    def phase(self) -> Phase:
        """The handover state's phase (the machine has none of its own)."""
        return self.handover.phase

    @property
    def gaze(self) -> str:
        """The behavior's gaze target (the ``gaze`` region's state), lost tracking aside."""
        return self._target_of[self._gaze_leaf[self._model.state[0]]]

    @property
    def tracking(self) -> TrackingState:
        """The ``tracking`` region's state: ``ok``, ``hold`` (tracking lost, the gaze held for
        ``tracking_lost.hold_s``) or ``lost`` (looking at the ``tracking_lost`` target)."""
        return self._tracking_leaf[self._model.state[1]]

    @property
    def lost(self) -> bool:
        """True while tracking is lost."""
        return self._model.state[1] != _TRACKING_OK

    def on_tracking(self, event: Event) -> None:
        """Apply ``tracking_lost`` / ``tracking_restored`` (stale or duplicate ones ignored)."""
        t = self._time(event)
        lost = event.kind is EventKind.TRACKING_LOST
        trigger = (EventKind.TRACKING_LOST if lost else EventKind.TRACKING_RESTORED).value
        if t is None or not self._model.trigger(trigger, t):
            self._ignored += 1  # no time, a duplicate loss, or a restore older than the loss

    def on_phase(self, change: PhaseChange) -> None:
        """The handover state moved (``change``): fire the ``phase`` trigger (its rules pick
        the gaze and start the new phase's segments)."""
        self._model.trigger("phase", change)

    def advance(self, t: float, tracking_end: float | None = None) -> None:
        """Feed the tick to the machine: fire the ``timer`` trigger at ``t``, whose rules start
        the segments due (the latest start wins) and end a tracking-loss hold.
        ``tracking_end``: the tracking's latest prediction of the phase's end.

        The trigger is skipped when it cannot fire anything: before the hold's end, and before
        the earliest start the machine's last schedule found while its evidence is unchanged
        (the handover state's revision, and the tracking's end estimate when a waiting start
        depends on it); the machine then decides exactly what a trigger would have."""
        if tracking_end is not None:
            self._tracking_end = tracking_end
        end = self._tracking_end
        if (
            t < self._hold_until
            and t < self._wake
            and (self._wake_revision is None or self._same_evidence(end))
        ):
            return
        self._model.trigger("timer", Tick(t, end))

    def _same_evidence(self, end: float) -> bool:
        """Whether the evidence the last schedule's ``wake`` holds for is unchanged."""
        if self._wake_revision != self.handover.revision:
            return False
        seen = self._wake_end
        return seen is None or seen == end or (seen != seen and end != end)

    def target(self, ctx: GazeContext) -> GazeTarget:
        """Where to look at ``ctx.t``: a target kind and its current point."""
        kind, point = self.aim(ctx.t, ctx.points, ctx.tracking_end)
        return GazeTarget(kind=kind, point=point)

    def aim(
        self, t: float, points: dict[str, np.ndarray], tracking_end: float
    ) -> tuple[str, np.ndarray]:
        """:meth:`target` from the context's fields, as the kind and the point (the engine's
        tick: no context or target value to build and read back)."""
        now = finite_float(t)
        t = now if now is not None else self.handover.phase_start
        end = finite_float(tracking_end)
        if end is None:
            end = math.nan
        self.advance(t, end)
        if not isinstance(points, dict):
            points = {}
        gaze, tracking = self._model.state
        lost_kind = self._lost_kind
        if tracking != _TRACKING_OK:
            if tracking == _TRACKING_HOLD and self._held is not None:
                return self._held
            return lost_kind, self._point(lost_kind, points)
        kind = self._kind_of_state[gaze]
        target = (kind, self._point(kind, points))
        if kind != lost_kind:
            self._point(lost_kind, points)  # keeps the last known face fresh for a tracking loss
        self._last_target = target
        return target

    # ----------------------------------------------------------------- helpers
    @staticmethod
    def _time(event: Event) -> float | None:
        for value in (getattr(event, "t", None), getattr(event, "detected_at", None)):
            t = finite_float(value)
            if t is not None:
                return t
        return None

    def _point(self, kind: str, points: dict[str, np.ndarray]) -> np.ndarray:
        """The point of ``kind`` in ``points`` if valid, else its last known or default one."""
        arr = self._valid(points.get(kind))
        if arr is not None:
            self._known[kind] = arr
            return arr
        if kind in self._known:
            return self._known[kind]
        default = self._defaults.get(kind)
        if default is not None:
            return default
        for name in ("face", "rest"):  # a missing target: look at the person, else at rest
            arr = self._valid(points.get(name))
            if arr is not None:
                return arr
            if name in self._known:
                return self._known[name]
            if name in self._defaults:
                return self._defaults[name]
        return np.full(3, np.nan)

    @staticmethod
    def _valid(p: object) -> np.ndarray | None:
        """``p`` as a finite (3,) float array, or None."""
        if p is None:
            return None
        arr = p if isinstance(p, np.ndarray) and p.dtype == np.float64 else _as3(p)
        if arr is None or arr.shape != (3,) or not np.isfinite(arr).all():
            return None
        return arr


def _as3(p: object) -> np.ndarray | None:
    try:
        return np.asarray(p, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        return None


def write_diagram(spec: BehaviorSpec, path: Path) -> None:
    """Write :func:`diagram` to ``path``; a ``.md`` file gets it in a fenced ``mermaid`` block
    (rendered by GitHub and most Markdown viewers), any other file the bare Mermaid text."""
    path = Path(path)
    text = diagram(spec).strip() + "\n"
    if path.suffix.lower() == ".md":
        text = f"```mermaid\n{text}```\n"
    path.write_text(text, encoding="utf-8")
