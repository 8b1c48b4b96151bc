"""What every recording reader returns, and the checks they share."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gazebot.phases.trajectory import Trajectory

# Length units accepted at the surface, as metres per unit.
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}


class RecordingError(ValueError):
    """A recording that cannot be used; the message starts with the file's name."""

    def __init__(self, source: str | Path, problem: str) -> None:
        self.source = str(source)
        self.problem = problem
        super().__init__(f"{self.source}: {problem}")


@dataclass(frozen=True)
class PointNames:
    """Which tracked names are the giver's hand, the receiver's hand and the giver's face.

    ``giver_face`` may be ``None`` (not tracked). Readers apply their own defaults when a name
    is ``None``.
    """

    giver_hand: str | None = None
    receiver_hand: str | None = None
    giver_face: str | None = None


@dataclass
class Recording:
    """A recording read from a file, in SI units.

    Attributes:
        trajectory: The samples (s, m).
        source: The file read.
        format: ``csv``, ``c3d``, ``rosbag``, ``mcap`` or ``pose-folder``.
        names: The names used for giver hand, receiver hand and giver face.
        available: Every point name the file has.
        unit: The file's length unit (converted to m).
        rate: Median sampling rate found (Hz; NaN with fewer than two samples).
        notes: What the reader had to work around (e.g. a file cut short), one line each.
    """

    trajectory: Trajectory
    source: str
    format: str
    names: tuple[str, str, str | None]
    available: tuple[str, ...]
    unit: str
    rate: float
    notes: tuple[str, ...] = ()

    def describe(self) -> str:
        """One line: format, names, units and rate (what the CLI prints)."""
        g, r, f = self.names
        face = f" giver_face={f}" if f else ""
        return (
            f"{self.source}: {self.format}, {len(self.trajectory)} samples at {self.rate:.1f} Hz, "
            f"file unit {self.unit} (shown in m, s); giver_hand={g} receiver_hand={r}{face}"
        )


def median_rate(t: np.ndarray) -> float:
    """Median sampling rate of the sorted times ``t`` (Hz)."""
    if t.shape[0] < 2:
        return float("nan")
    dt = np.diff(np.sort(t))
    dt = dt[dt > 0]
    return float(1.0 / np.median(dt)) if dt.size else float("nan")


def unit_scale(source: str | Path, unit: str) -> float:
    """Metres per ``unit``; a :class:`RecordingError` naming the accepted units otherwise."""
    key = unit.strip().lower()
    if key not in UNITS:
        raise RecordingError(source, f"unit {unit!r} is not one of {', '.join(UNITS)}")
    return UNITS[key]


def pick(
    source: str | Path, role: str, wanted: str | None, available: list[str], default: str | None
) -> str | None:
    """The name to use for ``role``: ``wanted``, else ``default`` when the file has it.

    Raises:
        RecordingError: ``wanted`` is not in the file (the message lists the names it has), or
            no name was given and the default is absent (for a required role).
    """
    have = ", ".join(available) or "(none)"
    if wanted is not None:
        if wanted in available:
            return wanted
        raise RecordingError(
            source,
            f"no point named {wanted!r} for {role}; the file has: {have}",
        )
    if default is not None and default in available:
        return default
    if role == "giver_face":
        return None
    flag = "--" + role.replace("_", "-")
    raise RecordingError(
        source,
        f"which point is {role}? pass {flag} NAME; the file has: {have}",
    )


def build(
    source: str | Path,
    fmt: str,
    t: np.ndarray,
    points: dict[str, np.ndarray],
    names: PointNames,
    unit: str,
    defaults: tuple[str | None, str | None, str | None],
    extra: dict[str, np.ndarray] | None = None,
    notes: tuple[str, ...] = (),
) -> Recording:
    """Pick the three points from ``points`` (name -> (N, 3) in the file's unit) and build the
    recording in metres (``notes``: see :attr:`Recording.notes`)."""
    available = sorted(points)
    scale = unit_scale(source, unit)
    g = pick(source, "giver_hand", names.giver_hand, available, defaults[0])
    r = pick(source, "receiver_hand", names.receiver_hand, available, defaults[1])
    f = pick(source, "giver_face", names.giver_face, available, defaults[2])
    n = t.shape[0]
    face = points[f] * scale if f else np.full((n, 3), np.nan)
    extra = extra or {}
    traj = Trajectory(
        t=t,
        giver_hand=points[g] * scale,  # type: ignore[index]
        receiver_hand=points[r] * scale,  # type: ignore[index]
        giver_face=face,
        gripper_closed=extra.get("gripper_closed", np.zeros(0)),
        load_share=extra.get("load_share", np.zeros(0)),
    )
    return Recording(
        traj,
        str(source),
        fmt,
        (g, r, f),
        tuple(available),
        unit,  # type: ignore[arg-type]
        median_rate(t),
        notes,
    )


def sample_streams(
    series: dict[str, list[tuple[float, float, float, float]]], max_gap: float
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Points sampled on the union of all stamps: ``(t, {name: (N, 3)})`` from per-name
    ``(t, x, y, z)`` rows (any order). Each name is linearly interpolated between its own
    samples, missing (NaN) outside them and across gaps longer than ``max_gap`` (s)."""
    t = np.unique(np.concatenate([[s[0] for s in v] for v in series.values()]))
    points: dict[str, np.ndarray] = {}
    for name, rows in series.items():
        a = np.array(sorted(rows))
        _, keep = np.unique(a[:, 0], return_index=True)
        a = a[keep]
        p = np.stack([np.interp(t, a[:, 0], a[:, k]) for k in (1, 2, 3)], axis=1)
        j = np.searchsorted(a[:, 0], t, side="right")
        exact = np.isin(t, a[:, 0])
        inside = (j > 0) & (j < a.shape[0])
        gap = np.full(t.shape[0], np.inf)
        gap[inside] = a[j[inside], 0] - a[j[inside] - 1, 0]
        p[~exact & (gap > max_gap)] = np.nan
        points[name] = p
    return t, points


def hold_values(t: np.ndarray, rows: list[tuple[float, float]]) -> np.ndarray:
    """The last of ``(stamp, value)`` ``rows`` at or before each time in ``t`` (NaN before the
    first; an empty ``rows`` gives an empty array: the value is not recorded)."""
    if not rows:
        return np.zeros(0)
    a = np.array(sorted(rows), dtype=float)
    j = np.searchsorted(a[:, 0], t, side="right") - 1
    out = np.full(t.shape[0], np.nan)
    out[j >= 0] = a[j[j >= 0], 1]
    return out
