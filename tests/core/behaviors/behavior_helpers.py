"""Helpers for the behavior tests: points that move, contexts and events."""

from __future__ import annotations

import math

import numpy as np

from gazebot.core.behaviors import BehaviorMachine
from gazebot.core.handover import PhaseChange, apply_event
from gazebot.core.types import Event, EventKind, GazeContext, Phase

FACE = np.array([1.0, 0.0, 1.6])
REST = np.array([0.4, 0.0, 0.8])
HANDOVER = np.array([0.6, 0.0, 1.0])


def hand_at(t: float) -> np.ndarray:
    """The giver's hand moves toward the robot over time."""
    return np.array([1.0 - 0.2 * t, 0.05 * t, 1.0])


def points(t: float, **override: np.ndarray) -> dict[str, np.ndarray]:
    pts = {
        "face": FACE,
        "hand": hand_at(t),
        "object": hand_at(t),
        "handover_location": HANDOVER,
        "rest": REST,
    }
    pts.update(override)
    return pts


def ctx(
    t: float, phase: Phase, start: float, end: float = math.nan, **override: np.ndarray
) -> GazeContext:
    """The context at ``t``; ``end`` is the tracking's predicted phase end. ``phase`` and
    ``start`` only document the caller's script: the machine reads its handover state."""
    return GazeContext(t, points(t, **override), tracking_end=end)


def ev(kind: str, t: float, **info: float) -> Event:
    return Event(EventKind(kind), t, t, dict(info))


def feed(machine: BehaviorMachine, event: Event) -> PhaseChange | None:
    """Apply ``event`` to the machine's own handover state; the machine follows the change."""
    return apply_event(machine.handover, machine, event)
