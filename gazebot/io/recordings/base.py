"""What every recording reader returns, and the checks they share."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gazebot.core.phases.trajectory import Trajectory

# Length units accepted at the surface, as metres per unit.
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}


class RecordingError(ValueError):
    """A recording that cannot be used; the message starts with the file's name."""

    def __init__(self, source: str | Path, problem: str) -> None:
        self.source = str(source)
        # One line, whatever a library's message held (the CLI prints one line per error).
        problem = " ".join(str(problem).split())
        self.problem = problem
        super().__init__(f"{self.source}: {problem}")


@dataclass(frozen=True)
class RecordingLimits:
    """What a recording may hold (SI units).

    Attributes:
        max_gap_s: Largest time step between two samples (s). Times must be finite and
            increasing; one outlier stamp (1e5 s, 1e308 s) would otherwise make every resampling
            step allocate gigabytes.
        min_step_s: Smallest time step between two samples (s): half a ROS stamp's
            resolution (1 ns) by default, so stamps 1 ns apart still pass after float
            rounding (motion capture runs below 10 kHz). A step of 1e-309 s is no sampling,
            and its rate (1 / step) overflows.
        workspace_m: Largest plausible coordinate magnitude (m, after the unit): a point
            beyond it (or infinite) is a missing sample, counted.
        max_chunk_bytes: Largest uncompressed size a compressed chunk (MCAP) may declare
            (bytes): a 32 kB file declaring 1 GiB would otherwise allocate it. rosbag2 and the
            ``mcap`` writers write chunks of 1 to 4 MiB.
        max_chunk_ratio: Largest ratio of a chunk's uncompressed to compressed size (for chunks
            declaring over 1 MiB): a decompression bomb (zstd, lz4) is refused before it is
            decompressed. Recorded ROS 2 messages compress 3 to 20 times.
    """

    max_gap_s: float = 60.0
    min_step_s: float = 0.5e-9
    workspace_m: float = 50.0
    max_chunk_bytes: int = 32 * 1024 * 1024
    max_chunk_ratio: float = 100.0

    def __post_init__(self) -> None:
        names = ("max_gap_s", "min_step_s", "workspace_m", "max_chunk_bytes", "max_chunk_ratio")
        for name in names:
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {v}")


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
        out_of_workspace: Samples of the three chosen points made missing because a
            coordinate was beyond :attr:`RecordingLimits.workspace_m` (or infinite).
    """

    trajectory: Trajectory
    source: str
    format: str
    names: tuple[str, str, str | None]
    available: tuple[str, ...]
    unit: str
    rate: float
    notes: tuple[str, ...] = ()
    out_of_workspace: int = 0

    def describe(self) -> str:
        """One line: format, names, units and rate (what the CLI prints)."""
        g, r, f = self.names
        face = f" giver_face={f}" if f else ""
        dropped = (
            f"; {self.out_of_workspace} point samples beyond the workspace made missing"
            if self.out_of_workspace
            else ""
        )
        return (
            f"{self.source}: {self.format}, {len(self.trajectory)} samples at {self.rate:.1f} Hz, "
            f"file unit {self.unit} (shown in m, s); giver_hand={g} receiver_hand={r}{face}"
            f"{dropped}"
        )


def median_rate(t: np.ndarray) -> float:
    """Median sampling rate of the sorted times ``t`` (Hz)."""
    if t.shape[0] < 2:
        return float("nan")
    dt = np.diff(np.sort(t))
    dt = dt[dt > 0]
    return float(1.0 / np.median(dt)) if dt.size else float("nan")


def check_times(
    source: str | Path,
    t: np.ndarray,
    where: Callable[[int], str],
    limits: RecordingLimits,
) -> None:
    """Times must be finite, increasing by at least ``limits.min_step_s`` and never more than
    ``limits.max_gap_s`` apart.

    Raises:
        RecordingError: Naming the sample (``where(i)``: "line 12", "frame 3", ...), its time
            and the previous one.
    """
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        i = int(bad[0])
        raise RecordingError(source, f"{where(i)}: time {t[i]} is not a finite number of seconds")
    if t.shape[0] < 2:
        return
    with np.errstate(over="ignore"):  # -1e308 then 1e308: an infinite gap, refused below
        dt = np.diff(t)
    bad = np.flatnonzero((dt < limits.min_step_s) | (dt > limits.max_gap_s))
    if not bad.size:
        return
    i = int(bad[0]) + 1
    if dt[i - 1] <= 0:
        raise RecordingError(
            source,
            f"{where(i)}: time {t[i]:.9g} s is not after the previous sample's {t[i - 1]:.9g} s "
            f"({where(i - 1)}); times must increase",
        )
    if dt[i - 1] < limits.min_step_s:
        raise RecordingError(
            source,
            f"{where(i)}: time {t[i]:.9g} s is only {dt[i - 1]:.3g} s after the previous sample "
            f"({where(i - 1)}); steps under {limits.min_step_s:g} s are refused",
        )
    raise RecordingError(
        source,
        f"{where(i)}: time {t[i]:.9g} s is {dt[i - 1]:.6g} s after the previous sample "
        f"({where(i - 1)}); gaps over {limits.max_gap_s:g} s are refused (--max-gap)",
    )


def in_workspace(p: np.ndarray, limit: float) -> tuple[np.ndarray, int]:
    """``p`` (N, 3) with every sample that has a coordinate beyond ``limit`` (or infinite)
    made missing (NaN), and how many were; compared without arithmetic, so 1e308 overflows
    nothing."""
    p = np.array(p, dtype=float)
    with np.errstate(invalid="ignore"):
        out = ((np.abs(p) > limit) | np.isinf(p)).any(axis=1)
    p[out] = np.nan
    return p, int(np.count_nonzero(out))


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
    extra: Mapping[str, np.ndarray] | None = None,
    notes: tuple[str, ...] = (),
    limits: RecordingLimits | None = None,
    where: Callable[[int], str] | None = None,
) -> Recording:
    """Pick the three points from ``points`` (name -> (N, 3) in the file's unit) and build the
    recording in metres (``notes``: see :attr:`Recording.notes`): times checked
    (:func:`check_times`; ``where(i)`` names sample ``i`` in the file, default "sample i"),
    points beyond the workspace made missing and counted."""
    limits = limits or RecordingLimits()
    check_times(source, t, where or (lambda i: f"sample {i + 1}"), limits)
    available = sorted(points)
    scale = unit_scale(source, unit)
    g = pick(source, "giver_hand", names.giver_hand, available, defaults[0])
    r = pick(source, "receiver_hand", names.receiver_hand, available, defaults[1])
    f = pick(source, "giver_face", names.giver_face, available, defaults[2])
    if g is None or r is None:  # pick raises for a hand it cannot name
        raise RecordingError(source, "no giver and receiver hand")
    n = t.shape[0]
    # Bounded in the file's unit first: scaling 1e308 mm to m is fine, squaring it later is not.
    chosen: dict[str, np.ndarray] = {}
    dropped = 0
    for name in {g, r, *([f] if f else [])}:
        p, k = in_workspace(points[name], limits.workspace_m / scale)
        chosen[name], dropped = p * scale, dropped + k
    face = chosen[f] if f else np.full((n, 3), np.nan)
    extra = extra or {}
    traj = Trajectory(
        t=t,
        giver_hand=chosen[g],
        receiver_hand=chosen[r],
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
        unit,
        median_rate(t),
        notes,
        dropped,
    )


Series = dict[str, list[tuple[float, float, float, float]]]  # name -> (t, x, y, z) rows


def bound_streams(
    source: str | Path, series: Series, limits: RecordingLimits
) -> tuple[Series, dict[str, int], Callable[[np.ndarray], Callable[[int], str]]]:
    """Stream readers' (bags, MCAP) checks before :func:`sample_streams`: a stamp that is not
    finite is an error; a row beyond the workspace (or not finite) is left out, so that
    interpolation neither overflows nor smears it into its neighbours. Returns the kept rows,
    how many rows each name lost, and ``namer(t)``: the ``where`` of :func:`build` for the
    union of stamps ``t`` (the message stamped ``t[i]`` and its topics)."""
    kept: Series = {}
    beyond: dict[str, int] = {}
    for name, rows in series.items():
        a = np.array(rows, dtype=float).reshape(-1, 4)
        if not np.isfinite(a[:, 0]).all():
            raise RecordingError(source, f"{name}: a message header stamp is not a finite time")
        xyz, beyond[name] = in_workspace(a[:, 1:], limits.workspace_m)
        ok = np.isfinite(xyz).all(axis=1)
        kept[name] = [tuple(r) for r in a[ok].tolist()]

    def namer(t: np.ndarray) -> Callable[[int], str]:
        def where(i: int) -> str:
            topics = sorted(n for n, rows in series.items() if any(r[0] == t[i] for r in rows))
            return f"the message stamped {t[i]:.9g} s on {', '.join(topics)}"

        return where

    return kept, beyond, namer


def sample_streams(series: Series, max_gap: float) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Points sampled on the union of all stamps: ``(t, {name: (N, 3)})`` from per-name
    ``(t, x, y, z)`` rows (any order). Each name is linearly interpolated between its own
    samples, missing (NaN) outside them and across gaps longer than ``max_gap`` (s)."""
    stamps = [[s[0] for s in v] for v in series.values()]
    t = np.unique(np.concatenate(stamps)) if any(stamps) else np.zeros(0)
    points: dict[str, np.ndarray] = {}
    for name, rows in series.items():
        if not rows:  # every row left out (beyond the workspace)
            points[name] = np.full((t.shape[0], 3), np.nan)
            continue
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
