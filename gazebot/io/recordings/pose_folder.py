"""A folder of per-body pose CSVs, one file per tracked body (e.g. the KTH handover dataset:
``giver_RHand_pose_saved.csv`` with columns ``x,y,z,q0,q1,q2,q3``, no time column, 120 Hz).
Names are the file names without ``_pose_saved.csv`` / ``.csv``; rows are samples at ``rate``.
A row exactly at the origin (x = y = z = 0) is a sample the tracker lost and the exporter wrote
as zeros (YCB-Handovers has such rows amid a hand's motion, the position and the first
quaternion element zeroed): it is missing, and the recording's notes count it. A tracked body
never sits at the capture volume's origin to the last digit.
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from gazebot.io.recordings.base import (
    PointNames,
    Recording,
    RecordingError,
    RecordingLimits,
    build,
)


def body_name(path: Path) -> str:
    """The body a pose file is named for: its file name without ``_pose_saved.csv``, ``_pose.csv``
    or ``.csv``."""
    name = path.name
    for suffix in ("_pose_saved.csv", "_pose.csv", ".csv"):
        if name.endswith(suffix):
            return name[: -len(suffix)]
    return name


def read_pose_folder(
    path: str | Path,
    names: PointNames | None = None,
    rate: float | None = None,
    unit: str = "m",
    limits: RecordingLimits | None = None,
) -> Recording:
    """Read the bodies of a pose folder sampled at ``rate`` (Hz, required: the files hold no
    time); ``limits``: see :class:`~gazebot.io.recordings.base.RecordingLimits`.

    Raises:
        RecordingError: No rate, no pose CSV, a file without x,y,z columns or with another row
            count, or a name the folder lacks.
    """
    path = Path(path)
    if rate is None:
        raise RecordingError(path, "a pose folder has no time column: pass --rate HZ")
    given = rate
    try:
        rate = float(rate)
    except (TypeError, ValueError):
        rate = math.nan
    if not 0.0 < rate < math.inf:
        raise RecordingError(path, f"--rate {given!r}: expected a finite rate > 0 in Hz")
    files = sorted(p for p in path.glob("*.csv"))
    points: dict[str, np.ndarray] = {}
    files_of: dict[str, str] = {}
    zeroed: dict[str, np.ndarray] = {}  # body -> its rows at the origin (lost tracking)
    for f in files:
        try:
            text = f.read_text(encoding="utf-8-sig")
        except UnicodeDecodeError as exc:
            raise RecordingError(
                f, f"not UTF-8 text (byte {exc.object[exc.start]:#04x} at offset {exc.start})"
            ) from None
        except OSError as exc:
            raise RecordingError(f, f"cannot read: {exc.strerror or exc}") from None
        lines = text.splitlines()
        header = [h.strip().lower() for h in lines[0].split(",")] if lines else []
        if not {"x", "y", "z"} <= set(header):
            continue  # e.g. a wrench file
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # "Empty input file": no rows is zero samples
                data = np.genfromtxt(
                    lines[1:],
                    delimiter=",",
                    usecols=[header.index(a) for a in "xyz"],
                    missing_values=("", "nan", "NaN"),
                    filling_values=np.nan,
                )
        except ValueError as exc:
            # numpy lists every bad row ("Line #1 (got 2 columns instead of 3)"): name the first.
            bad = re.search(r"Line #(\d+) \((.*?)\)", str(exc))
            where = f"line {int(bad.group(1)) + 1}: {bad.group(2)}" if bad else str(exc)
            raise RecordingError(f, f"not a numeric pose table ({where})") from None
        xyz = np.atleast_2d(data).reshape(-1, 3) if data.size else np.zeros((0, 3))
        lost = (xyz == 0.0).all(axis=1)
        xyz[lost] = np.nan
        points[body_name(f)], files_of[body_name(f)] = xyz, f.name
        zeroed[body_name(f)] = lost
    if not points:
        raise RecordingError(path, "no pose CSV with x, y, z columns in this folder")
    counts = {len(v) for v in points.values()}
    n = min(counts)
    points = {k: v[:n] for k, v in points.items()}
    with np.errstate(over="ignore"):  # (checked below: a rate so small the times overflow)
        t = np.arange(n) / float(rate)
    if n and not math.isfinite(float(t[-1])):
        raise RecordingError(
            path, f"--rate {rate!r} Hz puts the samples beyond any time (expected a rate in Hz)"
        )
    rec = build(
        path,
        "pose-folder",
        t,
        points,
        names or PointNames(),
        unit,
        (None, None, None),
        limits=limits,
        where=lambda i: f"row {i + 2}",
    )
    lost_rows = {b: int(zeroed[b][:n].sum()) for b in rec.names if b is not None}
    notes = tuple(
        f"{files_of[b]}: {k} row(s) at exactly (0, 0, 0) read as lost tracking"
        for b, k in lost_rows.items()
        if k
    )
    return replace(rec, notes=rec.notes + notes)
