"""The data-driven ``human-receiver`` behavior: gaze patterns and shift timings drawn from people.

:class:`HumanGazeModel` is the fitted distribution, shipped as YAML (the ``human:`` block of
``configs/behaviors/human-receiver.yaml``) because users do not have the annotations. It holds:

- ``patterns``: the gaze sequence of each phase (e.g. reach ``[face, hand]``, transfer ``[hand]``,
  retreat ``[hand, face]``) of every sequence that at least ``min_count`` annotated people showed,
  with its probability (its share among the kept ones);
- ``shifts``: for every kind of gaze shift (phase, position in the phase, from, to), a Beta
  distribution of *when* in the phase it happens (fraction of the phase), fitted by the method of
  moments to the annotated shifts.

For each handover, the machine draws a pattern and its shift fractions from its seeded generator
(equal seeds and inputs give equal runs) and runs them as ordinary segments.

This module only reads the fitted model; the fitting (which needs the annotations) lives in
:mod:`gazebot.apps.annotations.fit`, so ``behaviors`` does not depend on ``annotations``. Fit it
again from the data with::

    gazebot annotations fit-human path/to/handover-gaze-annotations --role receiver \\
        -o configs/behaviors/human-receiver.yaml
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from gazebot.core.behaviors.segment import AtFraction, Segment, check_target_name

#: A phase that has segments.
PhaseName = Literal["reach", "transfer", "retreat"]
PHASES: tuple[PhaseName, ...] = ("reach", "transfer", "retreat")


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class BetaFraction(_Strict):
    """Beta(a, b) over the fraction of the phase at which a shift happens."""

    a: float = Field(gt=0.0, allow_inf_nan=False)
    b: float = Field(gt=0.0, allow_inf_nan=False)
    n: int = Field(ge=0, description="number of annotated shifts fitted")
    mean: float = Field(ge=0.0, le=1.0)


class HumanShift(_Strict):
    """When the ``index``-th target of ``phase`` (``from_target`` -> ``to_target``) begins."""

    phase: PhaseName
    index: int = Field(ge=1)
    from_target: str
    to_target: str
    fraction: BetaFraction


class HumanPattern(_Strict):
    """One observed gaze sequence per phase and how often it occurred."""

    name: str
    probability: float = Field(gt=0.0, le=1.0)
    count: int = Field(ge=1)
    reach: list[str] = Field(default_factory=list)
    transfer: list[str] = Field(default_factory=list)
    retreat: list[str] = Field(default_factory=list)

    @model_validator(mode="after")
    def _check(self) -> HumanPattern:
        for phase in PHASES:
            for name in getattr(self, phase):
                check_target_name(name)
        return self


class HumanGazeModel(_Strict):
    """Fitted distribution of a role's gaze patterns and shift timings (see module docstring)."""

    role: Literal["giver", "receiver"] = "receiver"
    n_handovers: int = Field(ge=1)
    coverage: float = Field(ge=0.0, le=1.0, description="share of handovers the patterns cover")
    own_hand: str = "hand"
    other: str = "ignore"
    fitted_by: str = ""
    patterns: list[HumanPattern] = Field(min_length=1)
    shifts: list[HumanShift] = Field(default_factory=list)

    @model_validator(mode="after")
    def _check_shifts(self) -> HumanGazeModel:
        known = {(s.phase, s.index, s.from_target, s.to_target) for s in self.shifts}
        for p in self.patterns:
            for key in _shift_keys(p):
                if key not in known:
                    raise ValueError(f"patterns: {p.name} needs a shift {key} in 'shifts'")
        return self

    def targets(self) -> set[str]:
        """Every target any pattern looks at in any phase."""
        return {t for p in self.patterns for ph in PHASES for t in getattr(p, ph)}

    def probabilities(self) -> np.ndarray:
        """The patterns' probabilities, normalised to sum 1."""
        w = np.array([p.probability for p in self.patterns], dtype=float)
        return w / w.sum()

    def sample(self, rng: np.random.Generator) -> tuple[str, list[Segment]]:
        """Draw one handover's pattern and segments (fractions from the shift distributions)."""
        pattern = self.patterns[int(rng.choice(len(self.patterns), p=self.probabilities()))]
        table = {(s.phase, s.index, s.from_target, s.to_target): s.fraction for s in self.shifts}
        segments: list[Segment] = []
        for phase in PHASES:
            targets = getattr(pattern, phase)
            draws = sorted(
                float(rng.beta(table[key].a, table[key].b)) for key in _shift_keys(pattern, phase)
            )
            fractions = [0.0, *draws]
            for target, fraction in zip(targets, fractions, strict=True):
                at = AtFraction(fraction=min(max(fraction, 0.0), 1.0))
                segments.append(Segment(phase=phase, at=at, target=target))
        return pattern.name, segments


def _shift_keys(
    pattern: HumanPattern, only: PhaseName | None = None
) -> list[tuple[PhaseName, int, str, str]]:
    keys: list[tuple[PhaseName, int, str, str]] = []
    for phase in PHASES if only is None else (only,):
        targets = getattr(pattern, phase)
        keys += [(phase, i, targets[i - 1], targets[i]) for i in range(1, len(targets))]
    return keys
