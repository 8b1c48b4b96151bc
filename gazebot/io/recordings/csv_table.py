"""CSV recordings: a time column (``t``, ``time`` or ``timestamp``, s) and ``NAME_x, NAME_y,
NAME_z`` columns per tracked point (default names ``giver_hand``, ``receiver_hand``,
``giver_face``), optionally ``gripper_closed`` (0/1) and ``load_share`` (0..1). An empty cell,
``NaN`` or ``nan`` is a missing sample (motion-capture exports write NaN); a point with only some
coordinates is missing as a whole. ``unit`` (m, cm, mm) scales the coordinates.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from gazebot.core.phases.trajectory import POINTS
from gazebot.io.recordings.base import (
    PointNames,
    Recording,
    RecordingError,
    RecordingLimits,
    build,
)

TIME_COLUMNS = ("t", "time", "timestamp")
DEFAULTS = POINTS
_MISSING = {"", "nan", "-nan", "+nan"}


def read_csv(
    path: str | Path,
    names: PointNames | None = None,
    unit: str = "m",
    limits: RecordingLimits | None = None,
) -> Recording:
    """Read a CSV recording (see the module docstring); ``limits``: see
    :class:`~gazebot.io.recordings.base.RecordingLimits`.

    Raises:
        RecordingError: Not UTF-8, no header or time column, a cell that is not a number, an
            infinite value, a wrong row length, times not increasing or a gap over the limit,
            or a point name the file lacks (names the file, line and column).
    """
    path = Path(path)
    names = names or PointNames()
    try:
        with path.open(newline="", encoding="utf-8-sig") as fh:
            reader = csv.reader(fh)
            try:
                rows = list(reader)
            except csv.Error as exc:  # Python 3.10's reader rejects a NUL byte (3.11 reads it)
                where = f"line {reader.line_num}"
                raise RecordingError(path, f"{where}: not CSV text ({exc})") from None
    except UnicodeDecodeError as exc:
        byte = exc.object[exc.start]
        raise RecordingError(
            path, f"not UTF-8 text (byte {byte:#04x} at offset {exc.start}); save it as UTF-8"
        ) from None
    except OSError as exc:
        raise RecordingError(path, f"cannot read: {exc.strerror or exc}") from None
    if not rows:
        raise RecordingError(path, "empty file, expected a header row")
    header = [h.strip() for h in rows[0]]
    time_col = next((c for c in header if c.lower() in TIME_COLUMNS), None)
    if time_col is None:
        raise RecordingError(path, f"line 1: no time column (one of {', '.join(TIME_COLUMNS)})")
    seen: set[str] = set()
    for col in header:
        if col in seen:
            raise RecordingError(path, f"line 1, column '{col}': duplicate column")
        seen.add(col)
    values: list[list[float]] = []
    lines: list[int] = []
    for lineno, row in enumerate(rows[1:], start=2):
        if not row or all(not c.strip() for c in row):
            continue
        if len(row) != len(header):
            col = header[min(len(row), len(header) - 1)]  # the first cell missing (or extra)
            raise RecordingError(
                path, f"line {lineno}, column '{col}': expected {len(header)} cells, "
                f"got {len(row)}"
            )
        out = []
        for col, raw in zip(header, row, strict=True):
            text = raw.strip()
            if text.lower() in _MISSING:
                if col == time_col:
                    raise RecordingError(path, f"line {lineno}, column '{col}': time is missing")
                out.append(math.nan)
                continue
            try:
                v = float(text)
            except ValueError:
                raise RecordingError(
                    path, f"line {lineno}, column '{col}': not a number: {text!r}"
                ) from None
            if math.isinf(v):
                raise RecordingError(
                    path, f"line {lineno}, column '{col}': infinite value {text!r} (NaN = missing)"
                )
            if col == "load_share" and not 0.0 <= v <= 1.0:
                raise RecordingError(path, f"line {lineno}, column '{col}': expected 0..1, got {v}")
            if col == "gripper_closed" and v not in (0.0, 1.0):
                raise RecordingError(
                    path, f"line {lineno}, column '{col}': expected 0 or 1, got {v}"
                )
            out.append(v)
        values.append(out)
        lines.append(lineno)
    data = np.array(values, dtype=float).reshape(-1, len(header))
    columns = {h: data[:, i] for i, h in enumerate(header)}
    points: dict[str, np.ndarray] = {}
    for h in header:
        if h.endswith("_x"):
            base = h[:-2]
            if f"{base}_y" in columns and f"{base}_z" in columns:
                p = np.stack([columns[f"{base}_{axis}"] for axis in "xyz"], axis=1)
                p[np.isnan(p).any(axis=1)] = np.nan
                points[base] = p
    extra: dict[str, np.ndarray] = {
        k: columns[k] for k in ("gripper_closed", "load_share") if k in columns
    }
    return build(
        path,
        "csv",
        columns[time_col],
        points,
        names,
        unit,
        DEFAULTS,
        extra,
        limits=limits,
        where=lambda i: f"line {lines[i]}",
    )
