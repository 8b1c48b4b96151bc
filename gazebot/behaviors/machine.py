"""The behavior state machine: handover phases driven by events, gaze sub-states by time.

States (``transitions`` hierarchical machine, ``BehaviorMachine.state``):

- top level, one per handover phase: ``idle``, ``reach``, ``transfer``, ``retreat``, ``done``;
  phase events move between them;
- inside each phase, a gaze sub-state: ``carry`` (the previous phase's gaze continues until the
  phase's first segment starts), ``g0``, ``g1``, ... (segment *i* of the phase is active), ``lost``
  (tracking lost); ``idle`` has ``before`` and ``done`` has ``after`` instead of segments. A state
  reads e.g. ``reach_g1``.

Rules for imperfect event streams (``handle`` never raises):

- A phase event is applied when the phase graph allows it from the current phase and it is not
  older than the last applied phase event; otherwise it is ignored (counted in ``ignored``).
  Allowed: ``reach_started`` from idle/done (a new handover) and from transfer/retreat when newer
  (the previous ``handover_done`` was missed); ``transfer_started`` from idle/reach/done;
  ``retreat_started`` from idle/reach/transfer/done (a missed phase is skipped);
  ``handover_done`` from reach/transfer/retreat. A duplicate of the current phase's event is
  ignored (the first one's time stands).
- ``GazeContext.phase`` wins: when ``target(ctx)`` sees another phase than the events said, the
  machine moves to ``ctx.phase`` (started at ``ctx.phase_start``): the detector's current view
  beats a missed or late event.
- Robot events never change the phase; the latest of each kind in the current handover anchors
  ``{after: EVENT}`` segments and gives ``planned_duration``. A new handover keeps the robot
  events from its start on, plus a ``robot_reach_started`` sent since the previous
  ``handover_done`` (the robot may set off before the detector confirms the giver's reach).
- ``tracking_lost``: hold the current gaze point for ``tracking_lost.hold_s``, then look at the
  last known face position (the policy's target) until ``tracking_restored``; phases keep
  advancing meanwhile, so on restore the gaze resumes where the behavior now is.

"Halfway" (and any fraction of a phase) needs the phase's end online. The estimates:
``ctx.expected_phase_end`` (the phase detector's prediction from the giver's and the gripper's
motion), an ``expected_end`` in the phase event's info, and the robot's own motion end
(``robot_reach_started``/``robot_retreat_started`` time + ``planned_duration``); with none known,
``phase_durations_s`` of the spec (the human mean phase lengths). A reach ends when both hands
have arrived, so the latest estimate wins; a retreat ends when the giver's hand is back at rest
(the detector's ``handover_done``, usually before the robot is home), so the first known
estimate in the order above wins. The estimate is re-read every
tick; a segment that has started stays started, so a revised estimate never moves the gaze back.

Points: the returned point is ``ctx.points[kind]`` (the hand moves: it is read every call). When
that point is missing (NaN or an unknown named point) the last finite position of that kind is
used, then the face, then ``rest``; the point is NaN only if none was ever known.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

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

_PHASE_ORDER = {Phase.IDLE: 0, Phase.REACH: 1, Phase.TRANSFER: 2, Phase.RETREAT: 3, Phase.DONE: 4}
_PHASE_EVENTS = {
    EventKind.REACH_STARTED: Phase.REACH,
    EventKind.TRANSFER_STARTED: Phase.TRANSFER,
    EventKind.RETREAT_STARTED: Phase.RETREAT,
    EventKind.HANDOVER_DONE: Phase.DONE,
}
# Which phases each phase event may leave (see the module docstring).
_EVENT_SOURCES = {
    EventKind.REACH_STARTED: ("idle", "done", "transfer", "retreat"),
    EventKind.TRANSFER_STARTED: ("idle", "reach", "done"),
    EventKind.RETREAT_STARTED: ("idle", "reach", "transfer", "done"),
    EventKind.HANDOVER_DONE: ("reach", "transfer", "retreat"),
}
# Robot motions whose planned duration estimates the end of a phase.
_ROBOT_MOTION = {
    Phase.REACH: EventKind.ROBOT_REACH_STARTED,
    Phase.RETREAT: EventKind.ROBOT_RETREAT_STARTED,
}


def _finite(x: object) -> bool:
    """True for a finite real number (Python or NumPy scalar)."""
    try:
        return math.isfinite(x)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return False


@dataclass
class _Active:
    """A segment of the current phase with its (latched) start time."""

    segment: Segment
    started_at: float = math.nan  # NaN until it starts


class _Model:
    """The object whose ``state`` the ``transitions`` machine drives."""

    state: str


class BehaviorMachine:
    """Runs a :class:`BehaviorSpec`: feed events with :meth:`handle`, ask :meth:`target` each tick.

    Args:
        spec: The behavior.
        seed: Seed for behaviors that draw timings (``human-receiver``); equal seeds and equal
            inputs give equal outputs.
    """

    def __init__(self, spec: BehaviorSpec, seed: int = 0) -> None:
        self.spec = spec
        self._model = _Model()
        self._machine = self._build_machine()
        self.reset(seed)

    def reset(self, seed: int | None = None) -> None:
        """Forget everything (back to ``idle``), optionally with a new seed; cheaper than building
        a new machine."""
        if seed is not None:
            self.seed = int(seed)
        self.ignored = 0  # events ignored as stale, duplicated or not allowed from the phase
        self.pattern = ""  # name of the drawn pattern (data-driven behaviors)
        self._rng = np.random.default_rng(self.seed)
        self._phase = Phase.IDLE
        self._phase_start = -math.inf
        self._phase_expected_end = math.nan  # from the phase event's info
        self._last_phase_t = -math.inf
        self._handover_t0 = -math.inf  # events at or after this belong to the current handover
        self._robot: dict[EventKind, Event] = {}
        self._plan: dict[Phase, list[Segment]] = self._draw_plan()
        self._active: list[_Active] = []
        self._current = -1  # index into _active; -1 = carry
        self._carry = self.spec.before
        self._lost_since: float | None = None
        self._held: GazeTarget | None = None
        self._last_target: GazeTarget | None = None
        self._known: dict[str, np.ndarray] = {}
        self._model.to_idle()
        self._enter_segments(self._phase)

    # ----------------------------------------------------------------- construction
    def _n_children(self) -> int:
        if self.spec.human is not None:
            return self.spec.human.max_segments_per_phase()
        counts = [sum(s.phase == p.value for s in self.spec.segments) for p in SEGMENT_PHASES]
        return max(counts, default=0)

    def _build_machine(self) -> HierarchicalMachine:
        gaze = [f"g{i}" for i in range(self._n_children())]
        states = [
            {"name": "idle", "children": ["before", "lost"], "initial": "before"},
            *(
                {"name": p.value, "children": ["carry", *gaze, "lost"], "initial": "carry"}
                for p in SEGMENT_PHASES
            ),
            {"name": "done", "children": ["after", "lost"], "initial": "after"},
        ]
        self._leaves = tuple(f"{st['name']}_{c}" for st in states for c in st["children"])
        machine = HierarchicalMachine(
            model=self._model,
            states=states,
            initial="idle",
            ignore_invalid_triggers=True,
            auto_transitions=True,
        )
        for kind, sources in _EVENT_SOURCES.items():
            machine.add_transition(
                kind.value,
                list(sources),
                _PHASE_EVENTS[kind].value,
                conditions=[self._is_fresh],
            )
        return machine

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
        """Current state, e.g. ``idle_before``, ``reach_g1``, ``retreat_lost``."""
        return self._model.state

    @property
    def states(self) -> list[str]:
        """Every state :attr:`state` can take (leaf states, e.g. ``reach_g0``)."""
        return list(self._leaves)

    @property
    def phase(self) -> Phase:
        """The handover phase the machine believes in."""
        return self._phase

    @property
    def lost(self) -> bool:
        """True while tracking is lost."""
        return self._lost_since is not None

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
            if self._lost_since is None:
                self._lost_since = t
                self._held = self._last_target
                self._to_sub("lost")
            else:
                self.ignored += 1  # duplicate: the first loss time stands
        elif kind is EventKind.TRACKING_RESTORED:
            if self._lost_since is not None and t >= self._lost_since:
                self._lost_since = None
                self._held = None
                self._to_sub(self._gaze_child())
            else:
                self.ignored += 1
        else:
            old = self._robot.get(kind)
            if old is not None and old.t > t:
                self.ignored += 1  # an older copy arriving late
            else:
                info = event.info if isinstance(getattr(event, "info", None), dict) else {}
                self._robot[kind] = Event(kind, t, t, dict(info))

    def target(self, ctx: GazeContext) -> GazeTarget:
        """Where to look at ``ctx.t``: a target kind and its current point."""
        t = float(ctx.t) if _finite(ctx.t) else self._phase_start
        self._sync_phase(ctx, t)
        lost_kind = self.spec.tracking_lost.target
        if self._lost_since is not None:
            hold_end = self._lost_since + self.spec.tracking_lost.hold_s
            if t < hold_end and self._held is not None:
                return self._held
            return GazeTarget(lost_kind, self._point(lost_kind, ctx))
        kind = self._gaze_kind(t, ctx.expected_phase_end)
        self._to_sub(self._gaze_child())
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

    def _is_fresh(self, event: Event | None = None, t: float = math.nan) -> bool:
        return t >= self._last_phase_t

    def _handle_phase(self, kind: EventKind, t: float, event: Event) -> None:
        before = (self._phase, self._carry_at(t))
        if not self._model.trigger(kind.value, event=event, t=t):
            self.ignored += 1
            return
        self._last_phase_t = t
        info = getattr(event, "info", None) or {}
        expected = info.get("expected_end", math.nan) if isinstance(info, dict) else math.nan
        self._begin_phase(_PHASE_EVENTS[kind], t, before, expected)

    def _begin_phase(
        self, phase: Phase, t: float, before: tuple[Phase, str], expected: float = math.nan
    ) -> None:
        old_phase, carry = before
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
            # that began between the previous handover's end and this start (the detector may
            # confirm the giver's reach after the robot set off).
            self._robot = {
                k: e
                for k, e in self._robot.items()
                if e.t >= t or (k is EventKind.ROBOT_REACH_STARTED and e.t >= self._handover_t0)
            }
            self._plan = self._draw_plan()
            carry = self.spec.before
        self._phase = phase
        self._phase_start = t
        self._phase_expected_end = float(expected) if _finite(expected) else math.nan
        self._carry = carry
        self._enter_segments(phase)
        if self._lost_since is not None:
            self._to_sub("lost")

    def _enter_segments(self, phase: Phase) -> None:
        self._active = [_Active(s) for s in self._plan.get(phase, [])]
        self._current = -1
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
        start = float(ctx.phase_start) if _finite(ctx.phase_start) else t
        if phase is not self._phase:
            before = (self._phase, self._carry_at(start))
            getattr(self._model, f"to_{phase.value}")()
            self._last_phase_t = max(self._last_phase_t, start)
            self._begin_phase(phase, start, before)
        elif _finite(ctx.phase_start):
            self._phase_start = float(ctx.phase_start)

    # ----------------------------------------------------------------- gaze timing
    def _expected_end(self, ctx_end: float) -> float:
        start = self._phase_start
        estimates = (ctx_end, self._phase_expected_end, self._robot_motion_end())
        known = [end for end in estimates if _finite(end) and end > start]
        if not known:
            return start + self.spec.phase_durations_s.of(self._phase)
        if self._phase is Phase.REACH:
            # A reach ends when both hands have arrived: the later arrival wins.
            return float(max(known))
        # A retreat ends when the giver's hand is back at rest (the detector's handover_done),
        # often well before the robot is home: its prediction comes first.
        return float(known[0])

    def _robot_motion_end(self) -> float:
        """End of the robot's own reach/retreat (start + planned duration), NaN if unknown."""
        motion = _ROBOT_MOTION.get(self._phase)
        ev = self._robot.get(motion) if motion is not None else None
        if ev is None or ev.t < self._handover_t0:
            return math.nan
        planned = ev.info.get("planned_duration")
        return ev.t + float(planned) if _finite(planned) and planned > 0 else math.nan

    def _anchor_time(self, at: AtEvent) -> float:
        """When the ``after`` event of the current handover happened (NaN if it did not yet)."""
        if at.after is PHASE_START_EVENT.get(self._phase):
            return self._phase_start
        ev = self._robot.get(at.after)
        if ev is None or ev.t < self._handover_t0:
            return math.nan
        return ev.t

    def _update_active(self, t: float, ctx_end: float) -> None:
        if self._waiting == 0:
            return  # every segment of the phase has started (or never will)
        end: float | None = None
        changed = False
        for item in self._active:
            if math.isfinite(item.started_at):
                continue
            at = self.spec.resolve(item.segment)
            if isinstance(at, AtFraction):
                if end is None:
                    end = self._expected_end(ctx_end)
                start_t = self._phase_start + at.fraction * (end - self._phase_start)
            elif isinstance(at, AtEvent):
                start_t = self._anchor_time(at) + at.delay
            else:
                continue  # never
            if start_t <= t:
                item.started_at = max(start_t, self._phase_start)
                self._waiting -= 1
                changed = True
        if not changed:
            return
        best, best_t = -1, -math.inf
        for i, item in enumerate(self._active):
            if item.started_at >= best_t:  # NaN compares False: not started
                best, best_t = i, item.started_at
        self._current = best

    def _gaze_kind(self, t: float, ctx_end: float = math.nan) -> str:
        if self._phase is Phase.IDLE:
            return self.spec.before
        if self._phase is Phase.DONE:
            return self.spec.after
        self._update_active(t, ctx_end)
        if self._current < 0:
            return self._carry
        return self._active[self._current].segment.target

    def _carry_at(self, t: float) -> str:
        """The gaze kind of the current phase at time ``t`` (carried into the next phase)."""
        return self._gaze_kind(t)

    def _gaze_child(self) -> str:
        if self._lost_since is not None:
            return "lost"
        if self._phase is Phase.IDLE:
            return "before"
        if self._phase is Phase.DONE:
            return "after"
        return "carry" if self._current < 0 else f"g{self._current}"

    def _to_sub(self, child: str) -> None:
        name = f"{self._phase.value}_{child}"
        if self._model.state == name:
            return
        trigger: Callable[[], bool] | None = getattr(self._model, f"to_{name}", None)
        if trigger is not None:
            trigger()

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
