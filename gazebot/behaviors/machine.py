"""The behavior state machine: the ``transitions`` machine's states are the gaze decisions.

One ``transitions`` hierarchical machine (:func:`machine_definition`) with two parallel regions
under the root state ``behavior``:

- ``handover``: one state per handover phase (``idle``, ``reach``, ``transfer``, ``retreat``,
  ``done``), and inside each phase one state per gaze target, e.g. ``behavior_handover_reach_hand``.
  The current gaze target *is* this state. Phase events (``reach_started``, ...) move between the
  phases; the ``timer`` trigger shifts the gaze inside a phase when a segment's start time has
  come (each transition's condition names the segment's ``at``); ``detector`` adopts the phase
  detector's view when the events said otherwise. A phase entered within the same handover keeps
  the gaze it had (reach -> transfer -> retreat carry the target: leaf-to-leaf transitions); a
  new handover starts at the behavior's ``before`` target, ``done`` at its ``after`` target.
- ``tracking``: ``ok``, ``hold`` (tracking lost: the gaze point is held for
  ``tracking_lost.hold_s``) and ``lost`` (then the policy's target, the last known face, until
  ``tracking_restored``). Phases and gaze shifts keep advancing meanwhile, so on restore the gaze
  resumes where the behavior now is.

:meth:`BehaviorMachine.state` reads e.g. ``reach_hand`` (``reach_hand_lost`` while tracking is
lost). ``gazebot behaviors show NAME --diagram FILE`` draws the machine (:func:`diagram`).

What the machine keeps beside its state are times, not decisions: the current phase's start and
predicted end, the robot's events of this handover (anchors for ``{after: EVENT}``) and which
segments of the phase have started. The ``timer`` trigger is fired only when a segment's start
time has come (a tick with nothing due costs a few comparisons, not a ``transitions`` call).

Rules for imperfect event streams (``handle`` never raises):

- A phase event is applied when the phase graph allows it from the current phase and it is not
  older than the last applied phase event; otherwise it is ignored (counted in ``ignored``).
  Allowed: ``reach_started`` from idle/done (a new handover) and from transfer/retreat when newer
  (the previous ``handover_done`` was missed); ``transfer_started`` from idle/reach/done;
  ``retreat_started`` from idle/reach/transfer/done (a missed phase is skipped);
  ``handover_done`` from reach/transfer/retreat. A duplicate of the current phase's event is
  ignored (the first one's time stands).
- **The handover's reach starts with the first reach, the robot's or the giver's.** A
  ``robot_reach_started`` in idle/done starts the reach phase (the robot set off first, seed 6.3);
  a later or earlier report of the other reach start of the same handover moves the reach start to
  the earlier of the two. Other robot events never change the phase; the latest of each kind in
  the current handover anchors ``{after: EVENT}`` segments and gives ``planned_duration``.
- ``GazeContext.phase`` wins: when ``target(ctx)`` sees another phase than the events said, the
  machine moves to ``ctx.phase`` (started at ``ctx.phase_start``), except back to idle or done
  while the robot's reach has started the handover (the detector has not seen the giver move yet).

"Halfway" (and any fraction of a phase) needs the phase's end online. The estimates:
``ctx.expected_phase_end`` (the phase detector's prediction from the giver's and the gripper's
motion), an ``expected_end`` in the phase event's info, and the robot's own motion end
(``robot_reach_started``/``robot_retreat_started`` time + ``planned_duration``); with none known,
``phase_durations_s`` of the spec (the human mean phase lengths). A reach ends when both hands
have arrived, so the latest estimate wins; a retreat ends when the giver's hand is back at rest
(the detector's ``handover_done``, usually before the robot is home), so the first known
estimate in the order above wins. The estimate is re-read every tick; a segment that has started
stays started, so a revised estimate never moves the gaze back.

Points: the returned point is ``ctx.points[kind]`` (the hand moves: it is read every call). When
that point is missing (NaN or an unknown named point) the last finite position of that kind is
used, then the face, then ``rest``; the point is NaN only if none was ever known.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from transitions.extensions import HierarchicalMachine

from gazebot.behaviors.spec import (
    PHASE_START_EVENT,
    SEGMENT_PHASES,
    AtEvent,
    AtFraction,
    AtNever,
    BehaviorSpec,
    Segment,
)
from gazebot.types import Event, EventKind, GazeContext, GazeTarget, Phase

_ROOT, _HANDOVER, _TRACKING = "behavior", "behavior_handover", "behavior_tracking"
_PHASE_ORDER = {Phase.IDLE: 0, Phase.REACH: 1, Phase.TRANSFER: 2, Phase.RETREAT: 3, Phase.DONE: 4}
_PHASE_EVENTS = {
    EventKind.REACH_STARTED: Phase.REACH,
    EventKind.TRANSFER_STARTED: Phase.TRANSFER,
    EventKind.RETREAT_STARTED: Phase.RETREAT,
    EventKind.HANDOVER_DONE: Phase.DONE,
}
_EVENT_OF_PHASE = {phase: kind for kind, phase in _PHASE_EVENTS.items()}
# Which phases each phase event may leave (see the module docstring).
_EVENT_SOURCES = {
    EventKind.REACH_STARTED: (Phase.IDLE, Phase.DONE, Phase.TRANSFER, Phase.RETREAT),
    EventKind.TRANSFER_STARTED: (Phase.IDLE, Phase.REACH, Phase.DONE),
    EventKind.RETREAT_STARTED: (Phase.IDLE, Phase.REACH, Phase.TRANSFER, Phase.DONE),
    EventKind.HANDOVER_DONE: (Phase.REACH, Phase.TRANSFER, Phase.RETREAT),
}
# Phase moves within one handover: the gaze carries over (all others start a new handover or
# end it).
_CARRY = {
    (Phase.REACH, Phase.TRANSFER),
    (Phase.REACH, Phase.RETREAT),
    (Phase.TRANSFER, Phase.RETREAT),
}
# Robot motions whose planned duration estimates the end of a phase.
_ROBOT_MOTION = {
    Phase.REACH: EventKind.ROBOT_REACH_STARTED,
    Phase.RETREAT: EventKind.ROBOT_RETREAT_STARTED,
}
_TRACKING_STATES = ("ok", "hold", "lost")
_TRACKING_OK, _TRACKING_HOLD = f"{_TRACKING}_ok", f"{_TRACKING}_hold"


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
    """The targets the ``handover`` region can be in: ``before`` first, then sorted."""
    names = {spec.before, spec.after, *(s.target for s in spec.segments)}
    if spec.human is not None:
        names |= spec.human.targets()
    ordered = [spec.before, *sorted(names - {spec.before})]
    states = [_state_name(n) for n in ordered]
    if len(set(states)) != len(states):
        raise ValueError(f"behavior '{spec.name}': targets differing only in '_' vs '-'")
    return ordered


def _describe(at: AtFraction | AtEvent, phase: Phase) -> str:
    if isinstance(at, AtFraction):
        return f"{at.fraction:g} of the {phase.value}"
    return at.after.value + (f" + {at.delay:g} s" if at.delay else "")


def _slots(spec: BehaviorSpec) -> dict[Phase, list[tuple[int, str, str]]]:
    """Per phase, every ``(segment index, target, label)`` that can start in a handover
    (``never`` segments cannot)."""
    out: dict[Phase, list[tuple[int, str, str]]] = {p: [] for p in SEGMENT_PHASES}
    if spec.human is not None:
        for phase in SEGMENT_PHASES:
            seen = set()
            for pattern in spec.human.patterns:
                for i, target in enumerate(getattr(pattern, phase.value)):
                    if (i, target) not in seen:
                        seen.add((i, target))
                        out[phase].append((i, target, "start" if i == 0 else f"drawn shift {i}"))
        return out
    for phase in SEGMENT_PHASES:
        segs = [s for s in spec.segments if s.phase == phase.value]
        for i, seg in enumerate(segs):
            at = spec.resolve(seg)
            if not isinstance(at, AtNever):
                out[phase].append((i, seg.target, _describe(at, phase)))
    return out


#: Builds a transition condition from its key and label: ``("segment", phase, index, target)``,
#: ``("detector", phase)`` or ``("held",)``.
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
    targets = _gaze_targets(spec)
    before, after = _state_name(spec.before), _state_name(spec.after)
    gaze = [_state_name(t) for t in targets]
    phases = [
        {"name": "idle", "children": [before], "initial": before},
        *({"name": p.value, "children": gaze, "initial": before} for p in SEGMENT_PHASES),
        {"name": "done", "children": [after], "initial": after},
    ]
    states = [
        {
            "name": _ROOT,
            "parallel": [
                {"name": "handover", "children": phases, "initial": "idle"},
                {"name": "tracking", "children": list(_TRACKING_STATES), "initial": "ok"},
            ],
        }
    ]

    def leaf(phase: Phase, child: str | None = None) -> str:
        return f"{_HANDOVER}_{phase.value}" + (f"_{child}" if child else "")

    transitions: list[dict[str, Any]] = []
    for kind, sources in _EVENT_SOURCES.items():
        dest = _PHASE_EVENTS[kind]
        for source in sources:
            if (source, dest) in _CARRY:
                transitions += [
                    {"trigger": kind.value, "source": leaf(source, g), "dest": leaf(dest, g)}
                    for g in gaze
                ]
            else:
                transitions.append(
                    {"trigger": kind.value, "source": leaf(source), "dest": leaf(dest)}
                )
    for source in (Phase.IDLE, Phase.DONE):
        transitions.append(
            {
                "trigger": EventKind.ROBOT_REACH_STARTED.value,
                "source": leaf(source),
                "dest": leaf(Phase.REACH),
            }
        )
    for phase, slots in _slots(spec).items():
        for index, target, label in slots:
            transitions.append(
                {
                    "trigger": "timer",
                    "source": leaf(phase),
                    "dest": leaf(phase, _state_name(target)),
                    "conditions": [condition(("segment", phase, index, target), label)],
                }
            )
    for phase in _PHASE_ORDER:
        transitions.append(
            {
                "trigger": "detector",
                "source": _HANDOVER,
                "dest": leaf(phase),
                "conditions": [condition(("detector", phase), f"detector in {phase.value}")],
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
        },
    ]
    return {"states": states, "transitions": transitions, "initial": _ROOT}


def diagram(spec: BehaviorSpec) -> str:
    """The machine of ``spec`` as Mermaid ``stateDiagram-v2`` text, drawn by ``transitions``' own
    diagram support (``HierarchicalGraphMachine`` with ``graph_engine="mermaid"``) from the same
    :func:`machine_definition` the behavior runs on."""
    from transitions.extensions import HierarchicalGraphMachine

    class Drawn:
        """A model for the drawing only (never triggered)."""

    model = Drawn()
    HierarchicalGraphMachine(
        model=model,
        **machine_definition(spec),
        auto_transitions=False,
        graph_engine="mermaid",
        show_conditions=True,
        title=f"gaze behavior {spec.name}",
    )
    return str(model.get_graph().draw(None))  # type: ignore[attr-defined]


class _Model:
    """The object whose ``state`` the ``transitions`` machine drives."""

    state: list[str]


@dataclass
class _Segment:
    """A segment of the current phase: its slot and (latched) start time."""

    segment: Segment
    started_at: float = math.nan  # NaN until it starts


class BehaviorMachine:
    """Runs a :class:`BehaviorSpec`: feed events with :meth:`handle`, ask :meth:`target` each tick.

    Args:
        spec: The behavior.
        seed: Seed for behaviors that draw timings (``human-receiver``); equal seeds and equal
            inputs give equal outputs.
    """

    def __init__(self, spec: BehaviorSpec, seed: int = 0) -> None:
        self.spec = spec
        targets = _gaze_targets(spec)
        self._target_of = {_state_name(t): t for t in targets}
        self._model = _Model()
        self._firing = (Phase.IDLE, -1)  # the segment the next ``timer`` trigger may start
        self._hold_over = False
        self._detector_phase = Phase.IDLE
        definition = machine_definition(spec, self._condition)
        self._machine = HierarchicalMachine(
            model=self._model,
            **definition,
            auto_transitions=False,
            ignore_invalid_triggers=True,
        )
        # Leaf name -> (phase, gaze state) and tracking leaf -> name: parsing state names on
        # every tick would cost more than the lookups.
        self._leaf: dict[str, tuple[Phase, str]] = {}
        for phase in _PHASE_ORDER:
            for child in self._machine.get_state(f"{_HANDOVER}_{phase.value}").states:
                self._leaf[f"{_HANDOVER}_{phase.value}_{child}"] = (phase, child)
        self._tracking_leaf = {f"{_TRACKING}_{s}": s for s in _TRACKING_STATES}
        self.reset(seed)

    def _condition(self, key: tuple, label: str) -> Callable[[], bool]:
        """The runtime condition of a transition (see :data:`ConditionFactory`)."""
        if key[0] == "segment":
            _, phase, index, target = key

            def due() -> bool:
                # The segment the timer fires for, with this target (the drawn pattern's).
                return (
                    self._firing == (phase, index) and self._active[index].segment.target == target
                )

            condition = due
        elif key[0] == "detector":
            phase = key[1]

            def seen() -> bool:
                return self._detector_phase is phase

            condition = seen
        else:

            def held() -> bool:
                return self._hold_over

            condition = held
        condition.__name__ = label
        return condition

    def reset(self, seed: int | None = None) -> None:
        """Forget everything (back to ``idle``), optionally with a new seed; cheaper than building
        a new machine."""
        if seed is not None:
            self.seed = int(seed)
        self.ignored = 0  # events ignored as stale, duplicated or not allowed from the phase
        self.pattern = ""  # name of the drawn pattern (data-driven behaviors)
        self._rng = np.random.default_rng(self.seed)
        self._phase_start = -math.inf
        self._phase_expected_end = math.nan  # from the phase event's info
        self._last_phase_t = -math.inf
        self._handover_t0 = -math.inf  # events at or after this belong to the current handover
        self._robot_reach_t = math.nan  # the robot's reach start when it began this handover
        self._robot: dict[EventKind, Event] = {}
        self._plan: dict[Phase, list[Segment]] = self._draw_plan()
        self._active: list[_Segment] = []
        self._waiting = 0
        self._latest = -math.inf  # start time of the segment the gaze state follows
        self._lost_since = math.nan
        self._held: GazeTarget | None = None
        self._last_target: GazeTarget | None = None
        self._known: dict[str, np.ndarray] = {}
        self._machine.set_state(
            [f"{_HANDOVER}_idle_{_state_name(self.spec.before)}", f"{_TRACKING}_ok"]
        )

    def _draw_plan(self) -> dict[Phase, list[Segment]]:
        """The segments of the next handover (drawn from the data model for ``human``)."""
        if self.spec.human is not None:
            self.pattern, segments = self.spec.human.sample(self._rng)
        else:
            segments = list(self.spec.segments)
        return {p: [s for s in segments if s.phase == p.value] for p in SEGMENT_PHASES}

    # ----------------------------------------------------------------- public API
    def _where(self) -> tuple[Phase, str, str]:
        """(phase, gaze state, tracking state) read from the machine."""
        handover, tracking = self._model.state
        phase, gaze = self._leaf[handover]
        return phase, gaze, self._tracking_leaf[tracking]

    @property
    def state(self) -> str:
        """Current state, e.g. ``idle_face``, ``reach_hand``, ``retreat_face_lost`` (the phase, the
        gaze target's state and, while tracking is lost, ``hold`` or ``lost``)."""
        phase, gaze, tracking = self._where()
        return f"{phase.value}_{gaze}" + ("" if tracking == "ok" else f"_{tracking}")

    @property
    def states(self) -> list[str]:
        """Every value :attr:`state` can take."""
        out = []
        for phase, gaze in self._leaf.values():
            out += [
                f"{phase.value}_{gaze}",
                f"{phase.value}_{gaze}_hold",
                f"{phase.value}_{gaze}_lost",
            ]
        return out

    @property
    def phase(self) -> Phase:
        """The handover phase the machine is in."""
        return self._leaf[self._model.state[0]][0]

    @property
    def gaze(self) -> str:
        """The behavior's gaze target (the ``handover`` region's state), lost tracking aside."""
        return self._target_of[self._leaf[self._model.state[0]][1]]

    @property
    def tracking(self) -> str:
        """The ``tracking`` region's state: ``ok``, ``hold`` (tracking lost, the gaze held for
        ``tracking_lost.hold_s``) or ``lost`` (looking at the ``tracking_lost`` target)."""
        return self._tracking_leaf[self._model.state[1]]

    @property
    def lost(self) -> bool:
        """True while tracking is lost."""
        return self._model.state[1] != _TRACKING_OK

    def handle(self, event: Event) -> None:
        """Apply one event (phase or robot); never raises (see the module docstring)."""
        kind = self._kind(event)
        t = self._time(event)
        if kind is None or t is None:
            self.ignored += 1
            return
        if kind in _PHASE_EVENTS:
            self._handle_phase(kind, t, event)
        elif kind is EventKind.TRACKING_LOST:
            if self._trigger(kind.value):
                self._lost_since = t
                self._held = self._last_target
                self._hold_over = False
            else:
                self.ignored += 1  # duplicate: the first loss time stands
        elif kind is EventKind.TRACKING_RESTORED:
            if not (self.lost and t >= self._lost_since and self._trigger(kind.value)):
                self.ignored += 1
        else:
            self._handle_robot(kind, t, event)

    def target(self, ctx: GazeContext) -> GazeTarget:
        """Where to look at ``ctx.t``: a target kind and its current point."""
        t = float(ctx.t) if _finite(ctx.t) else self._phase_start
        self._sync_phase(ctx, t)
        self._run_timers(t, ctx.expected_phase_end)
        handover, tracking = self._model.state
        lost_kind = self.spec.tracking_lost.target
        if tracking != _TRACKING_OK:
            if tracking == _TRACKING_HOLD and self._held is not None:
                return self._held
            return GazeTarget(lost_kind, self._point(lost_kind, ctx))
        kind = self._target_of[self._leaf[handover][1]]
        target = GazeTarget(kind, self._point(kind, ctx))
        if kind != lost_kind:
            self._point(lost_kind, ctx)  # keeps the last known face fresh for a tracking loss
        self._last_target = target
        return target

    # ----------------------------------------------------------------- events
    @staticmethod
    def _kind(event: Event) -> EventKind | None:
        try:
            return EventKind(getattr(event, "kind", None))
        except ValueError:
            return None

    @staticmethod
    def _time(event: Event) -> float | None:
        for value in (getattr(event, "t", None), getattr(event, "detected_at", None)):
            if _finite(value):
                return float(value)
        return None

    def _trigger(self, name: str) -> bool:
        return bool(self._model.trigger(name))

    def _earlier_reach_start(self, t: float) -> bool:
        """The other reach of the current handover started at ``t``: the reach starts with the
        first (returns whether ``t`` belongs to this handover's reach)."""
        if self.phase is not Phase.REACH or t < self._handover_t0:
            return False
        self._phase_start = min(self._phase_start, t)
        return True

    def _handle_robot(self, kind: EventKind, t: float, event: Event) -> None:
        old = self._robot.get(kind)
        if old is not None and old.t > t:
            self.ignored += 1  # an older copy arriving late
            return
        info = event.info if isinstance(getattr(event, "info", None), dict) else {}
        self._robot[kind] = Event(kind, t, t, dict(info))
        if kind is not EventKind.ROBOT_REACH_STARTED:
            return
        if self.phase in (Phase.IDLE, Phase.DONE) and t >= self._last_phase_t:
            # The robot set off first: the handover's reach starts now.
            self._run_timers(t)
            old_phase = self.phase
            if self._trigger(kind.value):
                self._last_phase_t = t
                self._begin_phase(old_phase, Phase.REACH, t)
                self._robot_reach_t = t
        elif self._earlier_reach_start(t):
            self._robot_reach_t = t

    def _handle_phase(self, kind: EventKind, t: float, event: Event) -> None:
        phase = self.phase
        if (
            kind is EventKind.REACH_STARTED
            and math.isfinite(self._robot_reach_t)
            and self._earlier_reach_start(t)
        ):
            return  # the giver's reach of a handover the robot's reach started
        if t < self._last_phase_t:
            self.ignored += 1
            return
        self._run_timers(t)  # the gaze at the event's time is what carries on
        if not self._trigger(kind.value):
            self.ignored += 1
            return
        self._last_phase_t = t
        info = getattr(event, "info", None) or {}
        expected = info.get("expected_end", math.nan) if isinstance(info, dict) else math.nan
        self._begin_phase(phase, _PHASE_EVENTS[kind], t, expected)

    def _begin_phase(
        self, old_phase: Phase, phase: Phase, t: float, expected: float = math.nan
    ) -> None:
        """Bookkeeping after the machine entered ``phase`` at ``t`` (its state already moved)."""
        starts_new = (
            old_phase in (Phase.IDLE, Phase.DONE) or _PHASE_ORDER[phase] <= _PHASE_ORDER[old_phase]
        )
        if phase is not Phase.DONE and starts_new:
            # A new handover: forget the previous one's robot events and draw new timings.
            if old_phase is Phase.DONE:
                self._handover_t0 = self._phase_start
            elif old_phase is not Phase.IDLE:
                self._handover_t0 = t  # the previous handover_done was missed
            # Keep only what belongs to this handover: events since its start, and a robot reach
            # that began between the previous handover's end and this start.
            self._robot = {
                k: e
                for k, e in self._robot.items()
                if e.t >= t or (k is EventKind.ROBOT_REACH_STARTED and e.t >= self._handover_t0)
            }
            self._robot_reach_t = math.nan
            self._plan = self._draw_plan()
        self._phase_start = t
        self._phase_expected_end = float(expected) if _finite(expected) else math.nan
        self._active = [_Segment(s) for s in self._plan.get(phase, [])]
        self._latest = -math.inf
        # Segments that may still start; "never" ones do not count.
        self._waiting = sum(
            not isinstance(self.spec.resolve(a.segment), AtNever) for a in self._active
        )

    def _sync_phase(self, ctx: GazeContext, t: float) -> None:
        """Adopt the detector's phase when the events said otherwise (``ctx`` wins)."""
        phase = ctx.phase
        if type(phase) is not Phase:
            try:
                phase = Phase(phase)
            except ValueError:
                return
        current = self.phase
        start = float(ctx.phase_start) if _finite(ctx.phase_start) else t
        if phase is current:
            if _finite(ctx.phase_start):
                if phase is Phase.REACH and math.isfinite(self._robot_reach_t):
                    start = min(start, self._robot_reach_t)
                self._phase_start = start
            return
        if (
            phase in (Phase.IDLE, Phase.DONE)
            and current is Phase.REACH
            and math.isfinite(self._robot_reach_t)
        ):
            return  # the robot's reach started this handover; the giver has not moved yet
        self._run_timers(start)
        kind = _EVENT_OF_PHASE.get(phase)
        if kind is None or not self._trigger(kind.value):
            self._detector_phase = phase
            self._trigger("detector")
        self._last_phase_t = max(self._last_phase_t, start)
        self._begin_phase(current, phase, start)

    # ----------------------------------------------------------------- gaze timing
    def _expected_end(self, ctx_end: float, phase: Phase) -> float:
        start = self._phase_start
        estimates = (ctx_end, self._phase_expected_end, self._robot_motion_end(phase))
        known = [end for end in estimates if _finite(end) and end > start]
        if not known:
            return start + self.spec.phase_durations_s.of(phase)
        if phase is Phase.REACH:
            # A reach ends when both hands have arrived: the later arrival wins.
            return float(max(known))
        # A retreat ends when the giver's hand is back at rest (the detector's handover_done),
        # often well before the robot is home: its prediction comes first.
        return float(known[0])

    def _robot_motion_end(self, phase: Phase) -> float:
        """End of the robot's own reach/retreat (start + planned duration), NaN if unknown."""
        motion = _ROBOT_MOTION.get(phase)
        ev = self._robot.get(motion) if motion is not None else None
        if ev is None or ev.t < self._handover_t0:
            return math.nan
        planned = ev.info.get("planned_duration")
        return ev.t + float(planned) if _finite(planned) and planned > 0 else math.nan

    def _anchor_time(self, at: AtEvent, phase: Phase) -> float:
        """When the ``after`` event of the current handover happened (NaN if it did not yet)."""
        if at.after is PHASE_START_EVENT.get(phase):
            return self._phase_start
        ev = self._robot.get(at.after)
        if ev is None or ev.t < self._handover_t0:
            return math.nan
        return ev.t

    def _run_timers(self, t: float, ctx_end: float = math.nan) -> None:
        """Fire the ``timer`` trigger for what is due at ``t``: the segment that started last
        (its target becomes the gaze state) and the end of a tracking-loss hold."""
        if self.lost and not self._hold_over:
            if t >= self._lost_since + self.spec.tracking_lost.hold_s:
                self._hold_over = True
                self._trigger("timer")
        if self._waiting == 0:
            return  # every segment of the phase has started (or never will)
        phase = self.phase
        end: float | None = None
        best, best_t = -1, self._latest
        for i, item in enumerate(self._active):
            if math.isfinite(item.started_at):
                continue
            at = self.spec.resolve(item.segment)
            if isinstance(at, AtFraction):
                if end is None:
                    end = self._expected_end(ctx_end, phase)
                start_t = self._phase_start + at.fraction * (end - self._phase_start)
            elif isinstance(at, AtEvent):
                start_t = self._anchor_time(at, phase) + at.delay
            else:
                continue  # never
            if start_t <= t:
                item.started_at = max(start_t, self._phase_start)
                self._waiting -= 1
                if item.started_at >= best_t:  # the latest start wins; a tie: the later one
                    best, best_t = i, item.started_at
        if best >= 0:
            self._latest = best_t
            self._firing = (phase, best)
            self._trigger("timer")
            self._firing = (Phase.IDLE, -1)

    # ----------------------------------------------------------------- points
    def _point(self, kind: str, ctx: GazeContext) -> np.ndarray:
        points = ctx.points if isinstance(ctx.points, dict) else {}
        arr = self._valid(points.get(kind))
        if arr is not None:
            self._known[kind] = arr
            return arr
        if kind in self._known:
            return self._known[kind]
        for name in ("face", "rest"):  # a missing target: look at the person, else at rest
            arr = self._valid(points.get(name))
            if arr is not None:
                return arr
            if name in self._known:
                return self._known[name]
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
