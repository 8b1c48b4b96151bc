"""Gaze segments, the building block of a behavior: ``{phase, at, target}`` and the ``at`` forms.

``at`` is one of:

- a number or ``{fraction: f}``: that fraction (0..1) of the phase's expected duration;
- ``{after: EVENT, delay: s}``: ``s`` seconds after an event (``gazebot.core.types.EventKind``)
  of the current handover, e.g. ``robot_reach_ended`` or ``retreat_started``;
- ``never``: the segment never starts (lets a variant switch a shift off);
- ``$name``: the value of the behavior's parameter ``name``.

Both :mod:`gazebot.core.behaviors.spec` (the behavior YAML) and :mod:`gazebot.core.behaviors.human`
(the data-driven model, which draws segments) build on this module, so neither imports the other's
users. """

from __future__ import annotations

import math
from collections.abc import Collection
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator

from gazebot.core.types import EVENT_OF_PHASE, EventKind, Phase

#: Targets every robot provides (``GazeContext.points``); other names are robot-named points.
STANDARD_TARGETS = ("face", "hand", "object", "handover_location", "rest")
#: Targets the engine follows from the tracking (the giver's face and hand, the object, the
#: receiver's hand); any other target must be a point the robot defines (``points:``).
TRACKED_TARGETS = frozenset({"face", "hand", "object", "receiver_hand"})
#: Phases a segment can belong to (idle and done use ``before`` and ``after``).
SEGMENT_PHASES = (Phase.REACH, Phase.TRANSFER, Phase.RETREAT)
#: The event that starts each phase; ``{after: <that event>}`` is measured from the phase start.
PHASE_START_EVENT = EVENT_OF_PHASE

_TARGET_CHARS = set("abcdefghijklmnopqrstuvwxyz0123456789_-")


def check_target_name(name: str) -> str:
    """Validate a gaze target name (lower-case letters, digits, ``_`` and ``-``)."""
    if not isinstance(name, str) or not name or not set(name) <= _TARGET_CHARS:
        raise ValueError(
            f"a target name ({', '.join(STANDARD_TARGETS)} or a named point: lower-case letters, "
            "digits, '_' or '-')"
        )
    return name


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class AtFraction(_Strict):
    """Start at a fraction of the phase's expected duration (0 = phase start, 1 = its end)."""

    fraction: float = Field(ge=0.0, le=1.0)


class AtEvent(_Strict):
    """Start ``delay`` seconds after the latest ``after`` event of the current handover."""

    after: EventKind
    delay: float = Field(default=0.0, ge=0.0, allow_inf_nan=False)


class AtNever(_Strict):
    """Never start (written ``never`` in YAML)."""

    never: Literal[True] = True


At = AtFraction | AtEvent | AtNever


def parse_at(value: Any, parameters: Collection[str] | None = None) -> At | str:
    """Turn a YAML ``at`` value into an :data:`At` (or keep a ``$parameter`` reference; with
    ``parameters``, the names defined, a reference to another name is an error)."""
    if isinstance(value, AtFraction | AtEvent | AtNever):
        return value
    if isinstance(value, bool):
        raise ValueError(
            "a fraction 0..1, {fraction: f}, {after: EVENT, delay: s}, never or $param"
        )
    if isinstance(value, int | float):
        if not math.isfinite(value) or not 0.0 <= value <= 1.0:
            raise ValueError("a fraction of the phase between 0 and 1")
        return AtFraction(fraction=float(value))
    if isinstance(value, str):
        if value == "never":
            return AtNever()
        if value.startswith("$") and len(value) > 1:
            if parameters is not None and value[1:] not in parameters:
                raise ValueError(f"a defined parameter (known: {sorted(parameters)})")
            return value
    if isinstance(value, dict):
        if "fraction" in value:
            return AtFraction.model_validate(value)
        if "after" in value:
            return AtEvent.model_validate(value)
        if "never" in value:
            return AtNever.model_validate(value)
    raise ValueError("a fraction 0..1, {fraction: f}, {after: EVENT, delay: s}, never or $param")


class Segment(_Strict):
    """From ``at`` in ``phase`` on, look at ``target`` (until the phase's next segment starts)."""

    phase: Literal["reach", "transfer", "retreat"]
    at: AtFraction | AtEvent | AtNever | str = AtFraction(fraction=0.0)
    target: str

    @field_validator("at", mode="before")
    @classmethod
    def _parse_at(cls, value: Any, info: ValidationInfo) -> Any:
        # A loader that knows the behavior's parameter names passes them (``context``), so a
        # wrong ``$name`` is reported at its segment.
        return parse_at(value, (info.context or {}).get("parameters"))

    @field_validator("target")
    @classmethod
    def _check_target(cls, value: str) -> str:
        return check_target_name(value)
