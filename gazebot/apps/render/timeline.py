"""The handover timeline: one row per control tick (CSV) and a plot like the seed's Figure 6.5
(phases as colored bands: red reach, blue transfer, green retreat; the gaze target as a track;
the head joint angles below)."""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

PHASE_COLORS = {"reach": "#e06666", "transfer": "#6d9eeb", "retreat": "#93c47d"}
TARGET_ORDER = ("face", "hand", "object", "handover_location", "rest")


@dataclass(frozen=True)
class TickRecord:
    """What happened at one control tick (angles rad, points base frame m)."""

    t: float
    phase: str
    target: str
    head: dict[str, float]  # head joint goals
    eye_yaw: float
    eye_pitch: float
    target_point: np.ndarray
    hand: np.ndarray  # giver hand (simulation truth)
    face: np.ndarray  # giver face (simulation truth)
    head_measured: dict[str, float] = field(default_factory=dict)
    events: tuple[str, ...] = ()
    reach_start_time: float = math.nan  # giver's reach start - robot's (s), once both started


def _xyz(prefix: str, p: np.ndarray) -> dict[str, float]:
    return {f"{prefix}_{a}": float(v) for a, v in zip("xyz", p, strict=True)}


def write_timeline_csv(ticks: Sequence[TickRecord], path: str | Path) -> Path:
    """Write ``t, phase, target, <head joints (rad)>, eye_yaw, eye_pitch`` (rad) per tick, then
    the target point, giver hand and face (m), the measured head joints (``<joint>_measured``)
    and the events of the tick (``;``-separated)."""
    if not ticks:
        raise ValueError("no ticks to write")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    joints = list(ticks[0].head)
    fields = ["t", "phase", "target", *joints, "eye_yaw", "eye_pitch"]
    fields += [f"{p}_{a}" for p in ("target", "hand", "face") for a in "xyz"]
    fields += [f"{j}_measured" for j in joints] + ["events", "reach_start_time"]
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=fields)
        writer.writeheader()
        for k in ticks:
            row: dict[str, object] = {"t": f"{k.t:.6f}", "phase": k.phase, "target": k.target}
            row.update({j: f"{k.head.get(j, math.nan):.6f}" for j in joints})
            row.update(eye_yaw=f"{k.eye_yaw:.6f}", eye_pitch=f"{k.eye_pitch:.6f}")
            for name, p in (("target", k.target_point), ("hand", k.hand), ("face", k.face)):
                row.update({key: f"{v:.5f}" for key, v in _xyz(name, p).items()})
            row.update({f"{j}_measured": f"{k.head_measured.get(j, math.nan):.6f}" for j in joints})
            row["events"] = ";".join(k.events)
            row["reach_start_time"] = f"{k.reach_start_time:.4f}"
            writer.writerow(row)
    return path


def phase_spans(ticks: Sequence[TickRecord]) -> list[tuple[str, float, float]]:
    """Consecutive runs of one phase as ``(phase, t_start, t_end)``."""
    spans: list[tuple[str, float, float]] = []
    for k in ticks:
        if spans and spans[-1][0] == k.phase:
            spans[-1] = (k.phase, spans[-1][1], k.t)
        else:
            if spans:
                spans[-1] = (spans[-1][0], spans[-1][1], k.t)
            spans.append((k.phase, k.t, k.t))
    return spans


def plot_timeline(
    ticks: Sequence[TickRecord], path: str | Path, title: str = "Handover timeline"
) -> Path:
    """Save the timeline plot (PNG) with matplotlib's Agg back end."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    if not ticks:
        raise ValueError("no ticks to plot")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    t = np.array([k.t for k in ticks])
    targets = [k.target for k in ticks]
    levels = [n for n in TARGET_ORDER if n in targets] + sorted(set(targets) - set(TARGET_ORDER))
    y = np.array([levels.index(n) for n in targets])

    fig, (ax_t, ax_h) = plt.subplots(
        2, 1, figsize=(10, 5), sharex=True, gridspec_kw={"height_ratios": [1, 1.6]}
    )
    for ax in (ax_t, ax_h):
        for phase, t0, t1 in phase_spans(ticks):
            if phase in PHASE_COLORS:
                ax.axvspan(t0, t1, color=PHASE_COLORS[phase], alpha=0.35, lw=0)
    ax_t.step(t, y, where="post", color="black", lw=2.2)
    ax_t.set_yticks(range(len(levels)), levels)
    ax_t.set_ylim(-0.6, len(levels) - 0.4)
    ax_t.set_ylabel("gaze target")
    ax_t.set_title(title)
    # The robot's failure feedback (seed 3.2): where no reach met the timing.
    for k in ticks:
        if "robot_reach_infeasible" in k.events:
            ax_t.axvline(k.t, color="darkred", lw=1.5, ls="--")
            ax_t.annotate("reach infeasible", (k.t, len(levels) - 0.5), color="darkred",
                          fontsize=8, xytext=(3, 0), textcoords="offset points", va="top")
    handles = [Patch(color=c, alpha=0.5, label=p) for p, c in PHASE_COLORS.items()]
    ax_t.legend(handles=handles, loc="upper right", ncol=3, fontsize=8, frameon=False)

    for j in ticks[0].head:
        ax_h.plot(t, np.degrees([k.head[j] for k in ticks]), lw=1.8, label=f"{j} goal")
        if ticks[0].head_measured:
            meas = np.degrees([k.head_measured.get(j, np.nan) for k in ticks])
            ax_h.plot(t, meas, lw=1.0, ls="--", label=f"{j} measured")
    ax_h.plot(t, np.degrees([k.eye_yaw for k in ticks]), lw=1.0, color="0.4", label="eye yaw")
    ax_h.plot(t, np.degrees([k.eye_pitch for k in ticks]), lw=1.0, color="0.7", label="eye pitch")
    ax_h.set_ylabel("angle (deg)")
    ax_h.set_xlabel("time (s)")
    ax_h.legend(loc="best", fontsize=7, ncol=2)
    ax_h.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
