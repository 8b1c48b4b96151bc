"""A folder of per-body pose CSVs, one file per tracked body (e.g. the KTH handover dataset:
``giver_RHand_pose_saved.csv`` with columns ``x,y,z,q0,q1,q2,q3``, no time column, 120 Hz).
Names are the file names without ``_pose_saved.csv`` / ``.csv``; rows are samples at ``rate``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gazebot.recordings.base import (
    PointNames,
    Recording,
    RecordingError,
    RecordingLimits,
    build,
)


def body_name(path: Path) -> str:
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
    time); ``limits``: see :class:`~gazebot.recordings.base.RecordingLimits`.

    Raises:
        RecordingError: No rate, no pose CSV, a file without x,y,z columns or with another row
            count, or a name the folder lacks.
    """
    path = Path(path)
    if rate is None or not rate > 0:
        raise RecordingError(path, "a pose folder has no time column: pass --rate HZ")
    files = sorted(p for p in path.glob("*.csv"))
    points: dict[str, np.ndarray] = {}
    for f in files:
        with f.open(encoding="utf-8-sig") as fh:
            header = [h.strip().lower() for h in fh.readline().split(",")]
        if not {"x", "y", "z"} <= set(header):
            continue  # e.g. a wrench file
        try:
            data = np.genfromtxt(
                f,
                delimiter=",",
                skip_header=1,
                usecols=[header.index(a) for a in "xyz"],
                missing_values=("", "nan", "NaN"),
                filling_values=np.nan,
            )
        except ValueError as exc:
            raise RecordingError(f, f"not a numeric pose table ({exc})") from None
        points[body_name(f)] = np.atleast_2d(data).reshape(-1, 3)
    if not points:
        raise RecordingError(path, "no pose CSV with x, y, z columns in this folder")
    counts = {len(v) for v in points.values()}
    n = min(counts)
    points = {k: v[:n] for k, v in points.items()}
    t = np.arange(n) / float(rate)
    return build(
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
