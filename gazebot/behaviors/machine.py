"""The behavior state machine: the ``transitions`` machine's states are the gaze decisions.

The machine keeps **no phase of its own**: it reads the one
:class:`~gazebot.handover.HandoverState` (the engine's, or its own when run alone) and reacts to
its phase changes. :func:`machine_definition` builds one ``transitions`` hierarchical machine
with two parallel regions under the root state ``behavior``; every rule that decides the gaze
target is one of its transitions, with a named condition:

- ``gaze``: one state per gaze target (``behavior_gaze_face``, ``behavior_gaze_hand``, ...).
  Its transitions:

  * ``phase`` (the handover state changed phase) ``[new handover]`` -> the behavior's ``before``
    target (the reach of a new handover starts afresh), ``[handover done]`` -> its ``after``
    target, ``[same handover: the gaze carries]`` (internal: reach -> transfer -> retreat keep
    the target they had);
  * ``timer`` ``[PHASE: WHEN (RULE)]`` -> a segment's target, once per segment of the behavior:
    ``0.5 of the reach (end: latest of tracking, event, robot plan; else 1.01 s)`` or
    ``robot_reach_ended + 0.2 s``; when several start by the same tick the latest start wins
    (:func:`gazebot.behaviors.schedule.due_segments`).

- ``tracking``: ``ok`` -> ``hold`` on ``tracking_lost`` (the gaze point is held), ``hold`` ->
  ``lost`` on ``timer [held HOLD s]`` (then the policy's target, by default the last known
  face), back to ``ok`` on ``tracking_restored [after the loss]`` (an older restore is stale).
  Phases and gaze shifts keep advancing meanwhile, so on restore the gaze resumes where the
  behavior now is.

``gazebot behaviors show NAME --diagram FILE`` draws this machine, with the handover state's own
rule table (:data:`gazebot.handover.RULES`: first reach wins, grasp/release, stale events) as a
third region, from the same definitions that run (:func:`diagram`).

:meth:`BehaviorMachine.state` reads e.g. ``reach_hand`` (the handover state's phase, the gaze
state, and ``_hold``/``_lost`` while tracking is lost). :attr:`BehaviorMachine.origin`
(:class:`GazeOrigin`) names the rule that picked the current gaze state and the phase of that
rule, recorded when it picked it; a gaze carried into a later phase unchanged keeps that phase
and says which phase it was carried into.

Fraction timings need the phase's end online: :func:`gazebot.behaviors.schedule.expected_end`
combines the tracking's prediction (``GazeContext.tracking_end``), the phase event's
``expected_end`` and the robot's motion plan, else the spec's ``phase_durations_s``. It is
re-read every tick; a segment that has started stays started, so a revised estimate never moves
the gaze back.

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

from gazebot.behaviors.schedule import due_segments, end_rule, expected_end, segment_start
from gazebot.behaviors.spec import (
    SEGMENT_PHASES,
    AtEvent,
    AtFraction,
    AtNever,
    BehaviorSpec,
    Segment,
)
from gazebot.handover import RULES, HandoverState, PhaseChange
from gazebot.types import (
    Event,
    EventKind,
    GazeContext,
    GazeTarget,
    Phase,
)

_ROOT, _GAZE, _TRACKING = "behavior", "behavior_gaze", "behavior_tracking"
_TRACKING_STATES = ("ok", "hold", "lost")
_TRACKING_OK, _TRACKING_HOLD = f"{_TRACKING}_ok", f"{_TRACKING}_hold"
_NEW, _DONE, _CARRY = "new handover", "handover done", "same handover: the gaze carries"
_RESTORED = "after the loss"


def _finite(x: object) -> bool:
    """True for a finite real number (Python or NumPy scalar)."""
    try:
        return math.isfinite(x)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return False


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


#: Builds a transition condition from its key and label: ``("segment", phase, index, target)``,
#: ``("phase", name)``, ``("held",)`` or ``("restored",)``.
ConditionFactory = Callable[[tuple, str], Callable[[], bool]]


def _label_only(key: tuple, label: str) -> Callable[[], bool]:
    """A condition that only carries its label (for drawing; never evaluated)."""

    def condition() -> bool:
        raise RuntimeError("a drawn machine is not run")

    condition.__name__ = label
    return condition


def machine_definition(
    spec: BehaviorSpec, condition: ConditionFactory = _label_only
) -> dict[str, Any]:
    """The states, transitions and initial state of ``spec``'s machine (``transitions``
    keyword arguments); ``condition`` builds each transition condition (a callable whose
    ``__name__`` is the label the diagram shows)."""
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

    transitions: list[dict[str, Any]] = [
        {
            "trigger": "phase",
            "source": _GAZE,
            "dest": leaf(before),
            "conditions": [condition(("phase", _NEW), _NEW)],
        },
        {
            "trigger": "phase",
            "source": _GAZE,
            "dest": leaf(after),
            "conditions": [condition(("phase", _DONE), _DONE)],
        },
        {
            "trigger": "phase",
            "source": _GAZE,
            "dest": None,  # internal: the gaze state stays
            "conditions": [condition(("phase", _CARRY), _CARRY)],
        },
    ]
    for phase, slots in _slots(spec).items():
        for index, target, when in slots:
            transitions.append(
                {
                    "trigger": "timer",
                    "source": _GAZE,
                    "dest": leaf(_state_name(target)),
                    "conditions": [
                        condition(("segment", phase, index, target), f"{phase.value}: {when}")
                    ],
                }
            )
    hold = f"held {spec.tracking_lost.hold_s:g} s"
    transitions += [
        {
            "trigger": EventKind.TRACKING_LOST.value,
            "source": f"{_TRACKING}_ok",
            "dest": f"{_TRACKING}_hold",
        },
        {
            "trigger": "timer",
            "source": f"{_TRACKING}_hold",
            "dest": f"{_TRACKING}_lost",
            "conditions": [condition(("held",), hold)],
        },
        {
            "trigger": EventKind.TRACKING_RESTORED.value,
            "source": [f"{_TRACKING}_hold", f"{_TRACKING}_lost"],
            "dest": f"{_TRACKING}_ok",
            "conditions": [condition(("restored",), _RESTORED)],
        },
    ]
    return {"states": states, "transitions": transitions, "initial": _ROOT}


def _handover_region() -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """The handover state's rule table (:data:`gazebot.handover.RULES`) as a drawn region."""
    phases = [p.value for p in Phase]
    region = {"name": "handover", "children": phases, "initial": Phase.IDLE.value}
    transitions = []
    for rule in RULES:
        for source in rule.sources:
            dest = rule.dest if rule.dest is not None else source
            transitions.append(
                {
                    "trigger": rule.trigger.value,
                    "source": f"{_ROOT}_handover_{source.value}",
                    "dest": f"{_ROOT}_handover_{dest.value}",
                    "conditions": [_label_only((), rule.condition)],
                }
            )
    return region, transitions


def diagram(spec: BehaviorSpec) -> str:
    """The machine of ``spec`` as Mermaid ``stateDiagram-v2`` text, drawn by ``transitions``' own
    diagram support (``HierarchicalGraphMachine`` with ``graph_engine="mermaid"``) from the same
    :func:`machine_definition` the behavior runs on, plus the handover state's rule table (the
    phase the behavior reads) as the region ``handover``."""
    from transitions.extensions import HierarchicalGraphMachine

    class Drawn:
        """A model for the drawing only (never triggered)."""

    definition = machine_definition(spec)
    region, rules = _handover_region()
    definition["states"][0]["parallel"].insert(0, region)
    definition["transitions"] = rules + definition["transitions"]
    model = Drawn()
    HierarchicalGraphMachine(
        model=model,
        **definition,
        auto_transitions=False,
        graph_engine="mermaid",
        show_conditions=True,
        title=f"gaze behavior {spec.name}",
    )
    return str(model.get_graph().draw(None))  # type: ignore[attr-defined]


class _Model:
    """The object whose ``state`` the ``transitions`` machine drives."""

    state: list[str]


class BehaviorMachine:
    """Runs a :class:`BehaviorSpec`: feed events with :meth:`handle` (or phase changes with
    :meth:`on_phase`), ask :meth:`target` each tick.

    Args:
        spec: The behavior.
        seed: Seed for behaviors that draw timings (``human-receiver``); equal seeds and equal
            inputs give equal outputs.
        handover: The handover state to read the phase from (the engine's); ``None``: one of its
            own, fed by :meth:`handle`.
        defaults: Fallback positions (base frame, m) per target kind, for a kind never seen yet
            (the engine's: the robot's default face, its ``handover_location`` for the hand).
    """

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
        self._firing: tuple[Phase, int] = (Phase.IDLE, -1)
        self._change: PhaseChange | None = None
        self._hold_over = False
        self._machine = HierarchicalMachine(
            model=self._model,
            **machine_definition(spec, self._condition),
            auto_transitions=False,
            ignore_invalid_triggers=True,
        )
        self._gaze_leaf = {f"{_GAZE}_{s}": s for s in self._target_of}
        self._tracking_leaf = {f"{_TRACKING}_{s}": s for s in _TRACKING_STATES}
        self.reset(seed)

    def _condition(self, key: tuple, label: str) -> Callable[[], bool]:
        """The runtime condition of a transition (see :data:`ConditionFactory`)."""
        if key[0] == "segment":
            _, phase, index, target = key

            def condition() -> bool:
                # The segment the timer fires for, with this target (the drawn pattern's).
                return self._firing == (phase, index) and self._active[index][0].target == target

        elif key[0] == "phase":
            rule = key[1]

            def condition() -> bool:
                change = self._change
                if change is None:
                    return False
                if rule == _DONE:
                    return change.phase is Phase.DONE
                return change.new_handover is (rule == _NEW) and change.phase is not Phase.DONE

        elif key[0] == "held":

            def condition() -> bool:
                return self._hold_over

        else:

            def condition() -> bool:
                return self._restore_t >= self._lost_since

        condition.__name__ = label
        return condition

    def reset(self, seed: int | None = None) -> None:
        """Forget everything (back to ``idle``; a machine with its own handover state resets
        it too), optionally with a new seed; cheaper than building a new machine."""
        if seed is not None:
            self.seed = int(seed)
        if self._owns_handover:
            self.handover.reset()
        self._ignored = 0  # tracking events ignored as stale or duplicated
        self.pattern = ""  # name of the drawn pattern (data-driven behaviors)
        self._rng = np.random.default_rng(self.seed)
        self._plan: dict[Phase, list[Segment]] = self._draw_plan()
        self._active: list[list[Any]] = []  # [segment, started] of the current phase
        self._active_phase = Phase.IDLE
        self._waiting = 0
        self._latest = -math.inf  # start time of the segment the gaze state follows
        self._tracking_end = math.nan
        self._lost_since = math.nan
        self._restore_t = math.nan
        self._held: GazeTarget | None = None
        self._last_target: GazeTarget | None = None
        self._known: dict[str, np.ndarray] = {}
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
    def tracking(self) -> str:
        """The ``tracking`` region's state: ``ok``, ``hold`` (tracking lost, the gaze held for
        ``tracking_lost.hold_s``) or ``lost`` (looking at the ``tracking_lost`` target)."""
        return self._tracking_leaf[self._model.state[1]]

    @property
    def lost(self) -> bool:
        """True while tracking is lost."""
        return self._model.state[1] != _TRACKING_OK

    def handle(self, event: Event) -> PhaseChange | None:
        """Apply one event; never raises. Phase and robot events go through the handover state
        (its phase change, returned, moves the gaze), tracking events to the ``tracking``
        region."""
        kind = getattr(event, "kind", None)
        if kind is EventKind.TRACKING_LOST or kind is EventKind.TRACKING_RESTORED:
            self.on_tracking(event)
            return None
        t = self.handover.would_move(event)
        if t is not None:
            self.advance(t)  # what is due by the event's time is the gaze that carries on
        change = self.handover.apply(event)
        if change is not None:
            self.on_phase(change)
        return change

    def on_tracking(self, event: Event) -> None:
        """Apply ``tracking_lost`` / ``tracking_restored`` (stale or duplicate ones ignored)."""
        t = self._time(event)
        if t is None:
            self._ignored += 1
        elif event.kind is EventKind.TRACKING_LOST:
            if self._trigger(EventKind.TRACKING_LOST.value):
                self._lost_since = t
                self._held = self._last_target
                self._hold_over = False
            else:
                self._ignored += 1  # duplicate: the first loss time stands
        else:
            self._restore_t = t
            if not (self.lost and self._trigger(EventKind.TRACKING_RESTORED.value)):
                self._ignored += 1

    def on_phase(self, change: PhaseChange) -> None:
        """The handover state moved (``change``): fire the ``phase`` trigger and start the new
        phase's segments."""
        if change.new_handover:
            self._plan = self._draw_plan()
        self._change = change
        self._trigger("phase")
        self._change = None
        phase = change.phase
        if change.phase is Phase.DONE:
            self.origin = GazeOrigin(phase, "after", self.gaze, change.t)
        elif change.new_handover:
            self.origin = GazeOrigin(phase, "before", self.gaze, change.t)
        else:  # the gaze state stays: its rule is still the earlier phase's
            self.origin = replace(self.origin, carried_into=phase)
        self._active_phase = phase
        self._active = [[s, False] for s in self._plan.get(phase, [])]
        self._latest = -math.inf
        self._tracking_end = math.nan
        # Segments that may still start; "never" ones do not count.
        self._waiting = sum(
            not isinstance(self.spec.resolve(s), AtNever) for s, _ in self._active
        )

    def advance(self, t: float, tracking_end: float | None = None) -> None:
        """Fire the ``timer`` trigger for what is due at ``t``: the segment the gaze follows
        (see :func:`~gazebot.behaviors.schedule.due_segments`) and the end of a tracking-loss
        hold. ``tracking_end``: the tracking's latest prediction of the phase's end."""
        if tracking_end is not None:
            self._tracking_end = tracking_end
        if self.lost and not self._hold_over:
            if t >= self._lost_since + self.spec.tracking_lost.hold_s:
                self._hold_over = True
                self._trigger("timer")
        if self._waiting == 0:
            return  # every segment of the phase has started (or never will)
        phase = self._active_phase
        state = self.handover
        start = state.phase_start
        end = math.nan
        starts = []
        for segment, _started in self._active:
            at = self.spec.resolve(segment)
            if isinstance(at, AtFraction) and end != end:
                end = expected_end(
                    phase,
                    start,
                    (self._tracking_end, state.event_end, state.robot_motion_end()),
                    self.spec.phase_durations_s.of(phase),
                )
            anchor = state.anchor(at.after) if isinstance(at, AtEvent) else math.nan
            starts.append(max(segment_start(at, start, end, anchor), start))
        fired, best = due_segments(starts, [s for _, s in self._active], t, self._latest)
        for i in fired:
            self._active[i][1] = True
        self._waiting -= len(fired)
        if best is not None:
            self._latest = starts[best]
            self._firing = (phase, best)
            if self._trigger("timer"):
                self.origin = GazeOrigin(phase, f"segment {best}", self.gaze, t)
            self._firing = (Phase.IDLE, -1)

    def target(self, ctx: GazeContext) -> GazeTarget:
        """Where to look at ``ctx.t``: a target kind and its current point."""
        t = float(ctx.t) if _finite(ctx.t) else self.handover.phase_start
        end = ctx.tracking_end if _finite(ctx.tracking_end) else math.nan
        self.advance(t, end)
        gaze, tracking = self._model.state
        lost_kind = self.spec.tracking_lost.target
        if tracking != _TRACKING_OK:
            if tracking == _TRACKING_HOLD and self._held is not None:
                return self._held
            return GazeTarget(lost_kind, self._point(lost_kind, ctx))
        kind = self._target_of[self._gaze_leaf[gaze]]
        target = GazeTarget(kind, self._point(kind, ctx))
        if kind != lost_kind:
            self._point(lost_kind, ctx)  # keeps the last known face fresh for a tracking loss
        self._last_target = target
        return target

    # ----------------------------------------------------------------- helpers
    @staticmethod
    def _time(event: Event) -> float | None:
        for value in (getattr(event, "t", None), getattr(event, "detected_at", None)):
            if _finite(value):
                return float(value)
        return None

    def _trigger(self, name: str) -> bool:
        return bool(self._model.trigger(name))

    def _point(self, kind: str, ctx: GazeContext) -> np.ndarray:
        points = ctx.points if isinstance(ctx.points, dict) else {}
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
        arr = p if type(p) is np.ndarray and p.dtype == np.float64 else _as3(p)
        # Scalar checks: much cheaper than np.isfinite(...).all() on a 3-vector.
        if (
            arr is not None
            and arr.shape == (3,)
            and math.isfinite(arr[0])
            and math.isfinite(arr[1])
            and math.isfinite(arr[2])
        ):
            return arr
        return None


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
