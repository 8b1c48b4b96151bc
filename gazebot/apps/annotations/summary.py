"""Pattern shares and phase lengths of the annotated handovers, beside the seed's published ones."""

from __future__ import annotations

import statistics
from collections import Counter
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from gazebot.apps.annotations.loader import FPS, ROLES, AnnotationSet, LoadIssue, phase_runs
from gazebot.apps.annotations.reach import REACH_PATTERNS, reach_pattern
from gazebot.apps.annotations.rules import DEFAULT_RULE, GazeRule
from gazebot.apps.annotations.three_phase import (
    HANDOVER_PHASES,
    THREE_PHASE_PATTERNS,
    three_phase_pattern,
)

#: Seed figure 6.1 (section 6.3.1), percent of 288 handovers.
SEED_REACH: dict[str, dict[str, str]] = {
    "giver": {"Hand": "35.8", "Short Face-Hand": "30.2", "Face": "12.2", "Long Face-Hand": "9.0"},
    "receiver": {"Hand": "69.1", "Short Face-Hand": "21.5", "Face": "4.9", "Long Face-Hand": "2.8"},
}
#: Seed section 6.4.2 / figure 6.5, percent of handovers (as worded there).
SEED_THREE_PHASE: dict[str, dict[str, str]] = {
    "giver": {"Hand-Face": "25", "Face-Hand-Face": ">40", "Hand": "15.9"},
    "receiver": {"Hand-Face": ">50", "Face-Hand-Face": "25", "Hand": "17.4"},
}
#: Seed figure 6.1: mean reach length in frames.
SEED_REACH_FRAMES = {"giver": 8.10, "receiver": 7.53}


@dataclass(frozen=True)
class Summary:
    """Pattern shares (percent of all handovers) per role and the mean phase lengths.

    Attributes:
        n_handovers: Number of handovers read.
        reach: ``{role: {pattern: percent}}`` (section 6.3.1 patterns).
        three_phase: ``{role: {pattern: percent}}`` (section 6.4.2 patterns).
        counts: ``{"reach"|"three_phase": {role: {pattern: count}}}``.
        phase_frames: ``{role: {phase: mean length in frames}}`` over handovers having the phase.
        issues: Oddities found while loading.
        rule: How ``Own Hand`` and ``Other`` frames counted.
        own_hand_sensitivity: ``{"hand"|"other": {role: {pattern: percent}}}``: the reach shares
            with ``Own Hand`` counted as hand and as ``Other`` counts (``rule.other``), so a
            reader sees how much that counting choice moves the numbers (empty if not computed).
    """

    n_handovers: int
    reach: dict[str, dict[str, float]]
    three_phase: dict[str, dict[str, float]]
    counts: dict[str, dict[str, dict[str, int]]]
    phase_frames: dict[str, dict[str, float]]
    issues: tuple[LoadIssue, ...]
    rule: GazeRule
    own_hand_sensitivity: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """``{"n_handovers", "reach": {role: {pattern: percent}}, "three_phase": {...}}``."""
        return {
            "n_handovers": self.n_handovers,
            "reach": self.reach,
            "three_phase": self.three_phase,
        }

    def phase_seconds(self, role: str) -> dict[str, float]:
        """Mean phase lengths of ``role`` in seconds (8 fps video)."""
        return {k: v / FPS for k, v in self.phase_frames[role].items()}

    def format(self) -> str:
        """A plain-text report: ours beside the seed's published numbers."""
        lines = [
            f"{self.n_handovers} annotated handovers; Own Hand counts as {self.rule.own_hand}, "
            f"Other as {self.rule.other}",
            "",
            "Reach-phase patterns (seed 6.3.1, fig. 6.1), % of handovers:",
        ]
        lines += _table(self.reach, self.counts["reach"], SEED_REACH, REACH_PATTERNS)
        lines += self._sensitivity_lines()
        lines += ["", "Three-phase patterns (seed 6.4.2, fig. 6.5), % of handovers:"]
        lines += _table(
            self.three_phase, self.counts["three_phase"], SEED_THREE_PHASE, THREE_PHASE_PATTERNS
        )
        lines += ["", "Mean phase length, frames (s at 8 fps) over handovers having the phase:"]
        for role in ROLES:
            parts = [f"{p} {v:.2f} ({v / FPS:.2f} s)" for p, v in self.phase_frames[role].items()]
            lines.append(
                f"  {role:<9} " + ", ".join(parts) + f"  | seed reach {SEED_REACH_FRAMES[role]:.2f}"
            )
        lines += ["", f"Load issues: {len(self.issues)}"]
        lines += [f"  {issue}" for issue in self.issues[:20]]
        if len(self.issues) > 20:
            lines.append(f"  ... {len(self.issues) - 20} more")
        return "\n".join(lines)

    def _sensitivity_lines(self) -> list[str]:
        sens = self.own_hand_sensitivity
        if set(sens) != {"hand", "other"}:
            return []
        lines = [
            "",
            f"Sensitivity of the reach shares to Own Hand (as hand vs as Other, i.e. "
            f"{self.rule.other}), % of handovers:",
            f"  {'role':<9} {'pattern':<16} {'hand':>6} {'other':>6} {'change':>7} {'seed':>6}",
        ]
        for role in ROLES:
            for pattern in REACH_PATTERNS:
                a, b = sens["hand"][role][pattern], sens["other"][role][pattern]
                lines.append(
                    f"  {role:<9} {pattern:<16} {a:>6.1f} {b:>6.1f} {b - a:>+7.1f} "
                    f"{SEED_REACH[role].get(pattern, '-'):>6}"
                )
        return lines


def check_png_path(path: str | Path) -> Path:
    """``path`` as a Path if it names a ``.png`` file (not a folder); else ``ValueError``."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"plot path {path} is a directory; give a file name ending in .png")
    if path.suffix.lower() != ".png":
        raise ValueError(f"plot path {path} must end in .png (a PNG image is written)")
    return path


def _table(
    ours: dict[str, dict[str, float]],
    counts: dict[str, dict[str, int]],
    seed: dict[str, dict[str, str]],
    patterns: tuple[str, ...],
) -> list[str]:
    lines = [f"  {'role':<9} {'pattern':<16} {'ours':>6} {'(n)':>6} {'seed':>6}"]
    for role in ROLES:
        for pattern in patterns:
            s = seed[role].get(pattern, "-")
            lines.append(
                f"  {role:<9} {pattern:<16} {ours[role][pattern]:>6.1f} "
                f"{'(' + str(counts[role][pattern]) + ')':>6} {s:>6}"
            )
    return lines


def _percent(counter: Counter, patterns: tuple[str, ...], n: int) -> dict[str, float]:
    return {p: round(100.0 * counter.get(p, 0) / n, 1) if n else 0.0 for p in patterns}


def summarize(annotations: AnnotationSet, rule: GazeRule = DEFAULT_RULE) -> Summary:
    """Classify every handover's giver and receiver gaze and measure the phases; also the reach
    shares with ``Own Hand`` counted as hand and as ``rule.other`` (see
    :attr:`Summary.own_hand_sensitivity`)."""
    n = len(annotations.handovers)
    reach: dict[str, dict[str, float]] = {}
    three: dict[str, dict[str, float]] = {}
    counts: dict[str, dict[str, dict[str, int]]] = {"reach": {}, "three_phase": {}}
    frames: dict[str, dict[str, float]] = {}
    for role in ROLES:
        rc = Counter(reach_pattern(h, role, rule) for h in annotations.handovers)
        tc = Counter(three_phase_pattern(h, role, rule) for h in annotations.handovers)
        reach[role] = _percent(rc, REACH_PATTERNS, n)
        three[role] = _percent(tc, THREE_PHASE_PATTERNS, n)
        counts["reach"][role] = {p: rc.get(p, 0) for p in REACH_PATTERNS}
        counts["three_phase"][role] = {p: tc.get(p, 0) for p in THREE_PHASE_PATTERNS}
        frames[role] = mean_phase_frames(annotations, role)
    sensitivity = {
        label: {
            role: _percent(
                Counter(reach_pattern(h, role, alt) for h in annotations.handovers),
                REACH_PATTERNS,
                n,
            )
            for role in ROLES
        }
        for label, alt in (
            ("hand", replace(rule, own_hand="hand")),
            ("other", replace(rule, own_hand=rule.other)),
        )
    }
    return Summary(n, reach, three, counts, frames, annotations.issues, rule, sensitivity)


def mean_phase_frames(annotations: AnnotationSet, role: str) -> dict[str, float]:
    """Mean number of frames per phase (over the handovers that have the phase)."""
    out = {}
    for phase in HANDOVER_PHASES:
        lengths = [sum(p == phase for p in h.phase(role)) for h in annotations.handovers]
        lengths = [n for n in lengths if n > 0]
        out[phase] = round(statistics.fmean(lengths), 3) if lengths else 0.0
    return out


def phase_count(annotations: AnnotationSet, role: str) -> Counter:
    """How many separate runs of each phase the files hold (a file should hold one handover)."""
    c: Counter = Counter()
    for h in annotations.handovers:
        for label, _, _ in phase_runs(h.phase(role)):
            c[label] += 1
    return c


def plot_summary(summary: Summary, path: str | Path) -> Path:
    """Bar charts of ours against the seed's shares (numbers only where the seed gives one), as a
    PNG at ``path`` (must end in ``.png``; ``ValueError`` otherwise)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = check_png_path(path)
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), constrained_layout=True)
    for row, (title, ours, seed, patterns) in enumerate(
        (
            ("reach (6.3.1)", summary.reach, SEED_REACH, REACH_PATTERNS),
            ("three phases (6.4.2)", summary.three_phase, SEED_THREE_PHASE, THREE_PHASE_PATTERNS),
        )
    ):
        for col, role in enumerate(ROLES):
            ax = axes[row][col]
            xs = range(len(patterns))
            seed_vals = [_seed_number(seed[role].get(p)) for p in patterns]
            ax.bar([x - 0.2 for x in xs], [ours[role][p] for p in patterns], 0.4, label="ours")
            ax.bar([x + 0.2 for x in xs], seed_vals, 0.4, label="seed", alpha=0.7)
            ax.set_xticks(list(xs), patterns, rotation=20, fontsize=8)
            ax.set_ylabel("% of handovers")
            ax.set_title(f"{role}: {title}")
            ax.legend(fontsize=8)
    fig.suptitle(
        f"Gaze patterns in {summary.n_handovers} human-human handovers "
        "(seed bars: published shares; '>x' drawn at x)"
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _seed_number(text: str | None) -> float:
    """A seed share as a bar height (``>50`` drawn at 50; missing as 0)."""
    if not text:
        return 0.0
    return float(text.lstrip("><~ "))
