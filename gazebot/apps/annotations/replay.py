"""Replaying annotated handovers through a behavior: how humanlike is its gaze?

Each handover's phase labels (of the chosen role) become the events a phase detector would send,
frame by frame at 8 fps; the behavior's target at each frame is compared with the person's
labelled gaze. The replay is an idealised online run:

- phase events arrive at the first frame of each phase (``reach_started``, ``transfer_started``,
  ``retreat_started``; ``handover_done`` at the first frame after the retreat);
- ``ctx.expected_phase_end`` is the phase's true end (a perfect phase-end prediction);
- the robot moves in step with the person: ``robot_reach_started`` (with ``planned_duration`` = the
  reach length) at the reach start, ``robot_reach_ended`` and ``robot_grasped`` at the transfer
  start, ``robot_retreat_started`` (``planned_duration`` = the retreat length) at the retreat start,
  ``robot_retreat_ended`` at its end.

Compared frames: those in the person's reach, transfer and retreat whose label counts as face or
hand under the :class:`~gazebot.apps.annotations.rules.GazeRule` (ignored labels are skipped). A
behavior target ``object`` counts as hand; any other named point never matches.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from gazebot.apps.annotations.loader import FPS, AnnotatedHandover, AnnotationSet, phase_runs
from gazebot.apps.annotations.rules import DEFAULT_RULE, GazeRule
from gazebot.apps.annotations.three_phase import HANDOVER_PHASES
from gazebot.core.behaviors.machine import BehaviorMachine
from gazebot.core.behaviors.spec import BehaviorSpec
from gazebot.core.handover import apply_event
from gazebot.core.types import EVENT_OF_PHASE, Event, EventKind, GazeContext, Phase

_START_EVENT = {p.value: k for p, k in EVENT_OF_PHASE.items() if p is not Phase.DONE}
_AS_HAND = {"hand": "hand", "object": "hand", "face": "face"}
# Stand-in positions: only the target kind matters for the comparison.
_POINTS = {
    "face": np.array([1.0, 0.0, 1.6]),
    "hand": np.array([0.7, 0.0, 1.0]),
    "object": np.array([0.7, 0.0, 1.0]),
    "handover_location": np.array([0.6, 0.0, 1.0]),
    "rest": np.array([0.5, 0.0, 0.8]),
}


@dataclass(frozen=True)
class HandoverReplay:
    """Matches of one handover: ``matched``/``compared`` frames in total and per phase."""

    name: str
    matched: int
    compared: int
    by_phase: dict[str, tuple[int, int]]

    @property
    def share(self) -> float:
        return self.matched / self.compared if self.compared else math.nan


@dataclass(frozen=True)
class ReplayResult:
    """One behavior replayed over a set of handovers for one role."""

    behavior: str
    role: str
    handovers: tuple[HandoverReplay, ...]

    @property
    def share(self) -> float:
        """Share of all compared frames where the behavior matched the person (pooled)."""
        c = sum(h.compared for h in self.handovers)
        return sum(h.matched for h in self.handovers) / c if c else math.nan

    @property
    def mean_share(self) -> float:
        """Mean over handovers of the per-handover share."""
        shares = [h.share for h in self.handovers if h.compared]
        return float(np.mean(shares)) if shares else math.nan

    def phase_share(self, phase: str) -> float:
        m = sum(h.by_phase.get(phase, (0, 0))[0] for h in self.handovers)
        c = sum(h.by_phase.get(phase, (0, 0))[1] for h in self.handovers)
        return m / c if c else math.nan

    def to_json(self) -> dict:
        return {
            "behavior": self.behavior,
            "role": self.role,
            "n_handovers": len(self.handovers),
            "share": round(self.share, 4),
            "mean_share": round(self.mean_share, 4),
            "by_phase": {p: round(self.phase_share(p), 4) for p in HANDOVER_PHASES},
        }


def handover_events(phases: tuple[str, ...]) -> dict[int, list[Event]]:
    """Events by frame index for one person's phase labels (see the module docstring)."""
    events: dict[int, list[Event]] = {}

    def add(i: int, kind: EventKind, **info: float) -> None:
        t = i / FPS
        events.setdefault(i, []).append(Event(kind, t, t, dict(info)))

    in_handover = False
    for label, start, n in phase_runs(phases):
        if label in _START_EVENT:
            add(start, _START_EVENT[label])
            in_handover = True
            if label == "reach":
                add(start, EventKind.ROBOT_REACH_STARTED, planned_duration=n / FPS)
            elif label == "transfer":
                add(start, EventKind.ROBOT_REACH_ENDED)
                add(start, EventKind.ROBOT_GRASPED)
            else:
                add(start, EventKind.ROBOT_RETREAT_STARTED, planned_duration=n / FPS)
                add(start + n, EventKind.ROBOT_RETREAT_ENDED)
        elif in_handover:
            add(start, EventKind.HANDOVER_DONE)
            in_handover = False
    return events


def replay_handover(
    handover: AnnotatedHandover,
    spec: BehaviorSpec,
    role: str = "receiver",
    rule: GazeRule = DEFAULT_RULE,
    seed: int = 0,
    machine: BehaviorMachine | None = None,
) -> HandoverReplay:
    """Run ``spec`` along one handover's phases and count frames matching ``role``'s gaze.

    ``machine`` (built for ``spec``) is reset and reused when given, saving its construction.
    """
    phases = handover.phase(role)
    gaze = handover.gaze(role)
    events = handover_events(phases)
    # The phase end of every frame (the true end stands in for the detector's prediction).
    ends: list[float] = [math.nan] * len(phases)
    for label, start, n in phase_runs(phases):
        end = (start + n) / FPS if label in _START_EVENT else math.nan
        for i in range(start, start + n):
            ends[i] = end
    if machine is None or machine.spec is not spec:
        machine = BehaviorMachine(spec, seed=seed)
    else:
        machine.reset(seed)
    by_phase = {p: [0, 0] for p in HANDOVER_PHASES}
    for i, label in enumerate(phases):
        for event in events.get(i, ()):
            apply_event(machine.handover, machine, event)
        ctx = GazeContext(i / FPS, _POINTS, tracking_end=ends[i])
        kind = machine.target(ctx).kind
        human = rule.target(gaze[i])
        if label not in by_phase or human is None:
            continue
        by_phase[label][1] += 1
        by_phase[label][0] += int(_AS_HAND.get(kind) == human)
    matched = sum(m for m, _ in by_phase.values())
    compared = sum(c for _, c in by_phase.values())
    name = handover.path.name
    return HandoverReplay(name, matched, compared, {p: (m, c) for p, (m, c) in by_phase.items()})


def replay(
    annotations: AnnotationSet | Iterable[AnnotatedHandover],
    spec: BehaviorSpec,
    role: str = "receiver",
    rule: GazeRule = DEFAULT_RULE,
    seed: int = 0,
) -> ReplayResult:
    """Replay every handover (handover ``k`` uses seed ``seed + k``, so runs are reproducible)."""
    if role not in ("giver", "receiver"):
        raise ValueError(f"role must be 'giver' or 'receiver', got {role!r}")
    handovers = annotations.handovers if isinstance(annotations, AnnotationSet) else annotations
    machine = BehaviorMachine(spec, seed=seed)
    results = tuple(
        replay_handover(h, spec, role, rule, seed + k, machine) for k, h in enumerate(handovers)
    )
    return ReplayResult(spec.name, role, results)
