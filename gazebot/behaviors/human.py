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

Fit it again from the data with::

    gazebot annotations fit-human path/to/handover-gaze-annotations --role receiver \\
        -o configs/behaviors/human-receiver.yaml
"""

from __future__ import annotations

import math
import statistics
from collections import Counter, defaultdict
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from gazebot.behaviors.spec import AtFraction, Segment, check_target_name

if TYPE_CHECKING:
    from gazebot.annotations.loader import AnnotatedHandover, AnnotationSet
    from gazebot.annotations.rules import GazeRule

PHASES = ("reach", "transfer", "retreat")
FIT_COMMAND = (
    "gazebot annotations fit-human DIR --role {role} -o configs/behaviors/human-{role}.yaml"
)


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

    phase: Literal["reach", "transfer", "retreat"]
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

    def max_segments_per_phase(self) -> int:
        return max((len(getattr(p, ph)) for p in self.patterns for ph in PHASES), default=1)

    def targets(self) -> set[str]:
        return {t for p in self.patterns for ph in PHASES for t in getattr(p, ph)}

    def probabilities(self) -> np.ndarray:
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


def _shift_keys(pattern: HumanPattern, only: str | None = None) -> list[tuple[str, int, str, str]]:
    keys = []
    for phase in PHASES if only is None else (only,):
        targets = getattr(pattern, phase)
        keys += [(phase, i, targets[i - 1], targets[i]) for i in range(1, len(targets))]
    return keys


# ---------------------------------------------------------------------------- fitting


def phase_sequences(
    handover: AnnotatedHandover, role: str, rule: GazeRule
) -> dict[str, list[tuple[str, float]]]:
    """Per phase, the gaze targets in order with the fraction of the phase where each starts.

    Ignored frames are skipped but count towards the phase length (time passes).
    """
    gaze = handover.gaze(role)
    phases = handover.phase(role)
    out: dict[str, list[tuple[str, float]]] = {}
    for phase in PHASES:
        idx = [i for i, p in enumerate(phases) if p == phase]
        seq: list[tuple[str, float]] = []
        for k, i in enumerate(idx):
            target = rule.target(gaze[i])
            if target is not None and (not seq or seq[-1][0] != target):
                seq.append((target, k / len(idx)))
        out[phase] = seq
    return out


def pattern_name(seq: dict[str, list[tuple[str, float]]]) -> str:
    """E.g. ``FH-H-HF``: letters per phase (F face, H hand), ``.`` for a phase without gaze."""
    parts = ["".join(t[0].upper() for t, _ in seq[ph]) or "." for ph in PHASES]
    return "-".join(parts)


def _fit_beta(values: list[float]) -> BetaFraction:
    """Method-of-moments Beta; few or identical values get a concentration of 10 at their mean."""
    n = len(values)
    m = min(max(statistics.fmean(values), 0.02), 0.98) if values else 0.5
    var = statistics.pvariance(values) if n >= 2 else 0.0
    common = m * (1 - m) / var - 1.0 if var > 0 else 10.0
    if not math.isfinite(common) or common <= 0:
        common = 10.0
    a = min(max(m * common, 0.05), 1000.0)
    b = min(max((1 - m) * common, 0.05), 1000.0)
    return BetaFraction(a=round(a, 4), b=round(b, 4), n=n, mean=round(m, 4))


def fit_human_model(
    annotations: AnnotationSet,
    role: str = "receiver",
    rule: GazeRule | None = None,
    min_count: int = 3,
) -> HumanGazeModel:
    """Fit :class:`HumanGazeModel` to ``role``'s annotated gaze (patterns seen >= ``min_count``)."""
    from gazebot.annotations.rules import DEFAULT_RULE

    rule = rule or DEFAULT_RULE
    seqs = [phase_sequences(h, role, rule) for h in annotations.handovers]
    names = Counter(pattern_name(s) for s in seqs)
    kept = {name for name, c in names.items() if c >= min_count and name != ".-.-."}
    if not kept:
        raise ValueError(f"no gaze pattern occurs at least {min_count} times")
    n_kept = sum(names[k] for k in kept)
    example: dict[str, dict[str, list[tuple[str, float]]]] = {}
    shift_values: dict[tuple[str, int, str, str], list[float]] = defaultdict(list)
    for s in seqs:
        name = pattern_name(s)
        if name not in kept:
            continue
        example.setdefault(name, s)
        for phase in PHASES:
            for i in range(1, len(s[phase])):
                key = (phase, i, s[phase][i - 1][0], s[phase][i][0])
                shift_values[key].append(s[phase][i][1])
    patterns = [
        HumanPattern(
            name=name,
            probability=round(names[name] / n_kept, 4),
            count=names[name],
            **{ph: [t for t, _ in example[name][ph]] for ph in PHASES},
        )
        for name in sorted(kept, key=lambda k: (-names[k], k))
    ]
    shifts = [
        HumanShift(phase=k[0], index=k[1], from_target=k[2], to_target=k[3], fraction=_fit_beta(v))
        for k, v in sorted(shift_values.items())
    ]
    return HumanGazeModel(
        role=role,
        n_handovers=len(seqs),
        coverage=round(n_kept / len(seqs), 4),
        own_hand=rule.own_hand,
        other=rule.other,
        fitted_by=FIT_COMMAND.format(role=role),
        patterns=patterns,
        shifts=shifts,
    )


def retreat_face_delay_s(
    annotations: AnnotationSet, role: str, rule: GazeRule | None = None
) -> float:
    """Median delay (s) from the retreat start to the first face frame, over the ``role``'s
    Hand-Face handovers whose switch falls in the retreat ("slightly after", seed 6.4.2)."""
    from gazebot.annotations.loader import FPS
    from gazebot.annotations.rules import DEFAULT_RULE

    rule = rule or DEFAULT_RULE
    delays = []
    for h in annotations.handovers:
        s = phase_sequences(h, role, rule)
        if pattern_name(s).split("-")[:2] != ["H", "H"]:
            continue
        retreat = s["retreat"]
        n = sum(p == "retreat" for p in h.phase(role))
        if [t for t, _ in retreat] == ["hand", "face"]:
            delays.append(retreat[1][1] * n / FPS)
        elif [t for t, _ in retreat] == ["face"]:
            delays.append(0.0)
    return float(statistics.median(delays)) if delays else math.nan


def human_behavior_document(
    model: HumanGazeModel, phase_durations_s: dict[str, float]
) -> dict[str, Any]:
    """The YAML document of a data-driven behavior (``human-<role>``)."""
    return {
        "name": f"human-{model.role}",
        "description": f"gazes like a typical human {model.role}: patterns and shift timings drawn "
        f"from {model.n_handovers} annotated handovers",
        "source": "Kshirsagar et al. 2020 gaze annotations (seed 6.2); " + model.fitted_by,
        "before": "face",
        "after": "face",
        "phase_durations_s": {k: round(v, 4) for k, v in phase_durations_s.items()},
        "human": model.model_dump(mode="json"),
    }
