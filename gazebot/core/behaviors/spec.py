"""The behavior YAML format: a list of gaze segments per handover phase.

A behavior says where the robot looks before a handover (``before``), during each of its three
phases (``segments``) and after it (``after``). Each segment starts at a point ``at`` of its
phase and lasts until the next segment of that phase starts (or the phase ends)::

    name: face-hand-face
    parameters:
      reach_shift: 0.5                      # a fraction of the reach
    segments:
      - {phase: reach, at: 0.0, target: face}
      - {phase: reach, at: $reach_shift, target: hand}
      - {phase: retreat, at: {after: retreat_started, delay: 0.3}, target: face}

``at`` takes the forms :mod:`gazebot.core.behaviors.segment` lists (a fraction of the phase, a
delay after an event, ``never``, or ``$name``, a behavior parameter). Variants
(``extends: BASE``) change only parameters, so a variant like ``face-hand-face-as-studied`` is the
same behavior with other timings, not a copy.

Before the first segment of a phase starts, the gaze of the previous phase carries on.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator, model_validator

from gazebot.core.behaviors.human import HumanGazeModel
from gazebot.core.behaviors.segment import (
    PHASE_START_EVENT,
    SEGMENT_PHASES,
    STANDARD_TARGETS,
    At,
    AtEvent,
    AtFraction,
    AtNever,
    Segment,
    check_target_name,
    parse_at,
)
from gazebot.core.phases.durations import REACH_S, RETREAT_S, TRANSFER_S
from gazebot.core.types import Phase

__all__ = [
    "PHASE_START_EVENT",
    "SEGMENT_PHASES",
    "STANDARD_TARGETS",
    "At",
    "AtEvent",
    "AtFraction",
    "AtNever",
    "BehaviorSpec",
    "PhaseDurations",
    "Segment",
    "TrackingLostPolicy",
    "check_target_name",
    "parse_at",
]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class TrackingLostPolicy(_Strict):
    """What to do when the phase detector reports ``tracking_lost``.

    Hold the current gaze point for ``hold_s`` (a short dropout should not move the head), then
    look at ``target`` (by default the last known face position) until tracking is restored.
    """

    hold_s: float = Field(default=0.5, ge=0.0, allow_inf_nan=False)
    target: str = "face"

    @field_validator("target")
    @classmethod
    def _check_target(cls, value: str) -> str:
        return check_target_name(value)


class PhaseDurations(_Strict):
    """Fallback phase durations (s) for fraction timings when no online estimate exists.

    Defaults: the typical durations of the phase stream the engine reports (the giver's), from
    :mod:`gazebot.core.phases.durations`, the one place the detector's prediction reads too.
    """

    reach: float = Field(default=REACH_S, gt=0.0, allow_inf_nan=False)
    transfer: float = Field(default=TRANSFER_S, gt=0.0, allow_inf_nan=False)
    retreat: float = Field(default=RETREAT_S, gt=0.0, allow_inf_nan=False)

    def of(self, phase: Phase) -> float:
        """The fallback duration of ``phase`` (s); the reach's for a phase without one."""
        return float(getattr(self, phase.value, self.reach))


class BehaviorSpec(_Strict):
    """A gaze behavior: where to look before, during (per phase segments) and after a handover.

    Attributes:
        name: Behavior name (the YAML file's stem for files in a behaviors folder).
        description: One line for ``gazebot behaviors list``.
        source: Where the behavior comes from (e.g. ``seed 6.4.2``).
        extends: Base behavior whose segments this variant reuses with other ``parameters``.
        before: Target while idle (before the reach starts).
        after: Target once the handover is done.
        parameters: Named ``at`` values that segments refer to as ``$name``.
        segments: The gaze segments of the reach, transfer and retreat phases.
        tracking_lost: Policy while tracking is lost.
        phase_durations_s: Fallback phase durations for fraction timings.
        human: Data-driven timing model (``human-receiver``): segments are drawn per handover.
    """

    name: str = Field(json_schema_extra={"internal": True})  # the loader sets the file's stem
    description: str = ""
    source: str = ""
    extends: str | None = None
    before: str = "face"
    after: str = "face"
    parameters: dict[str, AtFraction | AtEvent | AtNever] = Field(default_factory=dict)
    segments: list[Segment] = Field(default_factory=list)
    tracking_lost: TrackingLostPolicy = TrackingLostPolicy()
    phase_durations_s: PhaseDurations = PhaseDurations()
    human: HumanGazeModel | None = None

    @field_validator("before", "after")
    @classmethod
    def _check_targets(cls, value: str) -> str:
        return check_target_name(value)

    @field_validator("parameters", mode="before")
    @classmethod
    def _parse_parameters(cls, value: Any) -> Any:
        if not isinstance(value, dict):
            return value
        out = {}
        for key, val in value.items():
            parsed = parse_at(val)
            if isinstance(parsed, str):
                raise ValueError("a parameter value: a fraction, {after: EVENT, delay: s} or never")
            out[key] = parsed
        return out

    @field_validator("segments")
    @classmethod
    def _check_references(cls, value: list[Segment], info: ValidationInfo) -> list[Segment]:
        parameters = info.data.get("parameters") or {}
        for i, seg in enumerate(value):
            if isinstance(seg.at, str) and seg.at[1:] not in parameters:
                raise ValueError(
                    f"segment {i}: 'at: {seg.at}' to name a parameter (known: {sorted(parameters)})"
                )
        return value

    @model_validator(mode="after")
    def _check_not_empty(self) -> BehaviorSpec:
        if not self.segments and self.human is None:
            raise ValueError("segments: at least one segment (or a 'human' timing model)")
        return self

    def resolve(self, segment: Segment) -> At:
        """The concrete ``at`` of ``segment`` (``$parameter`` references replaced)."""
        at = segment.at
        if isinstance(at, str):
            return self.parameters[at[1:]]
        return at

    def with_parameters(self, **overrides: Any) -> BehaviorSpec:
        """A variant of this behavior with some parameters changed (same segments)."""
        unknown = sorted(set(overrides) - set(self.parameters))
        if unknown:
            raise ValueError(f"unknown parameters {unknown} (known: {sorted(self.parameters)})")
        params = dict(self.parameters)
        for key, val in overrides.items():
            parsed = parse_at(val)
            if isinstance(parsed, str):
                raise ValueError(f"parameter {key}: a concrete value, not {val!r}")
            params[key] = parsed
        return self.model_copy(update={"parameters": params})

    def targets(self) -> set[str]:
        """Every target name the behavior may look at."""
        names = {self.before, self.after, self.tracking_lost.target}
        names.update(seg.target for seg in self.segments)
        if self.human is not None:
            names.update(self.human.targets())
        return names
