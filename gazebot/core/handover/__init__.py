"""The one handover state (:class:`HandoverState`): the phase stream merged from the phase
detector's evidence and the robot's events, which the engine reports and the behavior runs; the
phase's one owner (the detector reads it through :class:`HandoverView`, events reach it through
:func:`apply_event`)."""

from __future__ import annotations

from gazebot.core.handover.state import (
    RULES,
    HandoverState,
    HandoverView,
    PhaseChange,
    PhaseFollower,
    Rule,
    apply_event,
    event_source,
    machine_definition,
)

__all__ = [
    "RULES",
    "HandoverState",
    "HandoverView",
    "PhaseChange",
    "PhaseFollower",
    "Rule",
    "apply_event",
    "event_source",
    "machine_definition",
]
