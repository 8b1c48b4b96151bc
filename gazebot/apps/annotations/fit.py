"""Fit the data-driven ``human-<role>`` behavior
(:class:`~gazebot.core.behaviors.human.HumanGazeModel`)
to the annotated human-human handovers.

The fitting lives here, beside the annotations it reads, so that ``gazebot.core.behaviors`` only
reads the fitted YAML and never imports ``gazebot.apps.annotations`` (the dependency is one way:
annotations -> behaviors). Regenerate the shipped model with::

    gazebot annotations fit-human path/to/handover-gaze-annotations --role receiver \\
        -o configs/behaviors/human-receiver.yaml
"""

from __future__ import annotations

import math
import statistics
from collections import Counter, defaultdict
from typing import Any

from gazebot.apps.annotations.loader import FPS, AnnotatedHandover, AnnotationSet
from gazebot.apps.annotations.rules import DEFAULT_RULE, GazeRule
from gazebot.core.behaviors.human import (
    PHASES,
    BetaFraction,
    HumanGazeModel,
    HumanPattern,
    HumanShift,
)

FIT_COMMAND = (
    "gazebot annotations fit-human DIR --role {role} -o configs/behaviors/human-{role}.yaml"
)


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
