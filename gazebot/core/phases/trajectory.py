"""Tracked hand trajectories: arrays, the CSV format, and conversion to/from tracking frames.

CSV header (issue 3): ``t,giver_hand_x,giver_hand_y,giver_hand_z,receiver_hand_x,
receiver_hand_y,receiver_hand_z`` (s, m), optionally ``giver_face_x,giver_face_y,giver_face_z``,
``gripper_closed`` (0/1) and ``load_share`` (0..1). An empty cell, ``NaN`` or ``nan`` is a
missing sample (motion-capture exports write NaN). Other formats and point names:
:mod:`gazebot.io.recordings`.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gazebot.core.types import TrackingFrame

POINTS = ("giver_hand", "receiver_hand", "giver_face")
REQUIRED_COLUMNS = ("t", *(f"{p}_{a}" for p in POINTS[:2] for a in "xyz"))
OPTIONAL_COLUMNS = (*(f"giver_face_{a}" for a in "xyz"), "gripper_closed", "load_share")


def _nan_points(n: int) -> np.ndarray:
    return np.full((n, 3), np.nan)


@dataclass
class Trajectory:
    """Samples of the tracked points, one row per time.

    Attributes:
        t: Sample times (N,) in s. Not necessarily increasing: :meth:`cleaned` sorts them.
        giver_hand: Giver hand positions (N, 3) in m; a NaN row is a missing sample.
        receiver_hand: Receiver hand (or robot gripper) positions (N, 3) in m.
        giver_face: Giver face positions (N, 3) in m (all NaN when not tracked).
        gripper_closed: Gripper state per sample (N,) as 1.0/0.0, NaN when unknown.
        load_share: Robot load share per sample (N,) in 0..1, NaN when unknown.
    """

    t: np.ndarray
    giver_hand: np.ndarray
    receiver_hand: np.ndarray
    giver_face: np.ndarray = field(default_factory=lambda: _nan_points(0))
    gripper_closed: np.ndarray = field(default_factory=lambda: np.zeros(0))
    load_share: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        self.t = np.asarray(self.t, dtype=float).reshape(-1)
        n = self.t.shape[0]
        for name in POINTS:
            arr = np.asarray(getattr(self, name), dtype=float)
            if name == "giver_face" and arr.size == 0:
                arr = _nan_points(n)
            if arr.shape != (n, 3):
                raise ValueError(f"{name} must have shape ({n}, 3), got {arr.shape}")
            setattr(self, name, arr)
        for name in ("gripper_closed", "load_share"):
            arr = np.asarray(getattr(self, name), dtype=float).reshape(-1)
            if arr.size == 0:
                arr = np.full(n, np.nan)
            if arr.shape != (n,):
                raise ValueError(f"{name} must have shape ({n},), got {arr.shape}")
            setattr(self, name, arr)

    @classmethod
    def of_hands(cls, t: np.ndarray, giver_hand: np.ndarray, receiver_hand: np.ndarray,
                 unknown: np.ndarray | None = None) -> Trajectory:
        """``Trajectory(t, giver_hand, receiver_hand)`` from float64 arrays already shaped
        ``(N,)``, ``(N, 3)``, ``(N, 3)`` (the samples the online detector keeps), without the
        constructor's conversions and checks: it builds one per analysis. Face, gripper and
        load share are unknown (NaN), as the constructor makes them: views of one all-NaN
        ``(N, 5)`` block, ``unknown`` if given (the caller's, reused between calls), else a new
        one."""
        traj = cls.__new__(cls)
        traj.t = t
        traj.giver_hand = giver_hand
        traj.receiver_hand = receiver_hand
        if unknown is None:
            unknown = np.empty((t.shape[0], 5))  # (one block for the three: one allocation)
            unknown.fill(np.nan)
        traj.giver_face = unknown[:, :3]
        traj.gripper_closed = unknown[:, 3]
        traj.load_share = unknown[:, 4]
        return traj

    def __len__(self) -> int:
        return int(self.t.shape[0])

    @property
    def duration(self) -> float:
        """Time spanned by the samples (s); 0 for fewer than two samples."""
        return float(np.nanmax(self.t) - np.nanmin(self.t)) if len(self) > 1 else 0.0

    def cleaned(self) -> tuple[Trajectory, int, int]:
        """Samples sorted by time with non-finite and duplicate times dropped.

        Returns:
            ``(trajectory, n_reordered, n_dropped)``: how many samples arrived out of order and
            how many were dropped (non-finite time, or a time already seen: the first is kept).
        """
        finite = np.isfinite(self.t)
        idx = np.flatnonzero(finite)
        n_reordered = int(np.count_nonzero(np.diff(self.t[idx]) < 0))
        order = idx[np.argsort(self.t[idx], kind="stable")]
        ts = self.t[order]
        keep = np.ones(ts.shape[0], dtype=bool)
        keep[1:] = ts[1:] > ts[:-1]
        order = order[keep]
        n_dropped = len(self) - order.shape[0]
        return self.take(order), n_reordered, n_dropped

    def take(self, index: np.ndarray) -> Trajectory:
        """The samples at ``index`` (a new trajectory)."""
        return Trajectory(
            t=self.t[index],
            giver_hand=self.giver_hand[index],
            receiver_hand=self.receiver_hand[index],
            giver_face=self.giver_face[index],
            gripper_closed=self.gripper_closed[index],
            load_share=self.load_share[index],
        )

    def frames(self) -> list[TrackingFrame]:
        """The samples as tracking frames (in stored order)."""
        return list(self.iter_frames())

    def iter_frames(self) -> Iterable[TrackingFrame]:
        """Yield one :class:`TrackingFrame` per sample (in stored order)."""
        for i in range(len(self)):
            g = self.gripper_closed[i]
            s = self.load_share[i]
            yield TrackingFrame(
                t=float(self.t[i]),
                giver_hand=self.giver_hand[i].copy(),
                receiver_hand=self.receiver_hand[i].copy(),
                giver_face=self.giver_face[i].copy(),
                gripper_closed=None if math.isnan(g) else bool(g >= 0.5),
                load_share=None if math.isnan(s) else float(s),
            )

    @classmethod
    def from_frames(cls, frames: Sequence[TrackingFrame]) -> Trajectory:
        """Stack tracking frames into arrays (missing gripper/load values become NaN)."""
        n = len(frames)

        def stack(name: str) -> np.ndarray:
            if n == 0:
                return _nan_points(0)
            return np.array([np.asarray(getattr(f, name), float).reshape(3) for f in frames])

        def opt(v: object) -> float:
            return math.nan if v is None else float(v)  # type: ignore[arg-type]

        return cls(
            t=np.array([f.t for f in frames], dtype=float),
            giver_hand=stack("giver_hand"),
            receiver_hand=stack("receiver_hand"),
            giver_face=stack("giver_face"),
            gripper_closed=np.array([opt(f.gripper_closed) for f in frames], dtype=float),
            load_share=np.array([opt(f.load_share) for f in frames], dtype=float),
        )

    def to_csv(self, path: str | Path) -> Path:
        """Write the CSV format read by :func:`load_trajectory_csv` (NaN -> empty cell)."""
        path = Path(path)
        cols = list(REQUIRED_COLUMNS)
        has_face = bool(np.isfinite(self.giver_face).any())
        has_grip = bool(np.isfinite(self.gripper_closed).any())
        has_load = bool(np.isfinite(self.load_share).any())
        if has_face:
            cols += [f"giver_face_{a}" for a in "xyz"]
        if has_grip:
            cols.append("gripper_closed")
        if has_load:
            cols.append("load_share")

        def cell(v: float) -> str:
            return "" if math.isnan(v) else repr(float(v))

        with path.open("w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(cols)
            for i in range(len(self)):
                row = [cell(self.t[i]), *map(cell, self.giver_hand[i])]
                row += list(map(cell, self.receiver_hand[i]))
                if has_face:
                    row += list(map(cell, self.giver_face[i]))
                if has_grip:
                    row.append(cell(self.gripper_closed[i]))
                if has_load:
                    row.append(cell(self.load_share[i]))
                w.writerow(row)
        return path


class TrajectoryFormatError(ValueError):
    """A malformed trajectory CSV; the message names the file, line and column."""

    def __init__(self, source: str | Path, line: int, column: str, problem: str):
        self.source = str(source)
        self.line = line
        self.column = column
        super().__init__(f"{self.source}: line {line}, column '{column}': {problem}")


def load_trajectory_csv(path: str | Path) -> Trajectory:
    """Read a trajectory CSV (see the module docstring).

    Raises:
        FileNotFoundError: ``path`` does not exist.
        TrajectoryFormatError: Missing required column, unknown column, wrong number of cells,
            a non-numeric or infinite value, or a missing time (names line and column).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"trajectory file not found: {path}")
    with path.open(newline="", encoding="utf-8-sig") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        raise TrajectoryFormatError(path, 1, "<header>", "empty file, expected a header row")
    header = [h.strip() for h in rows[0]]
    for col in REQUIRED_COLUMNS:
        if col not in header:
            raise TrajectoryFormatError(path, 1, col, "required column missing from the header")
    known = set(REQUIRED_COLUMNS) | set(OPTIONAL_COLUMNS)
    for col in header:
        if col not in known:
            raise TrajectoryFormatError(path, 1, col, f"unknown column (known: {sorted(known)})")
        if header.count(col) > 1:
            raise TrajectoryFormatError(path, 1, col, "duplicate column")
    face_cols = [c for c in header if c.startswith("giver_face_")]
    if face_cols and len(face_cols) != 3:
        raise TrajectoryFormatError(path, 1, face_cols[0], "giver_face needs _x, _y and _z")

    data: dict[str, list[float]] = {c: [] for c in header}
    for lineno, row in enumerate(rows[1:], start=2):
        if not row or all(not c.strip() for c in row):
            continue  # blank line
        if len(row) != len(header):
            col = header[min(len(row), len(header) - 1)]
            raise TrajectoryFormatError(
                path, lineno, col, f"expected {len(header)} cells, got {len(row)}"
            )
        for col, raw in zip(header, row, strict=True):
            text = raw.strip()
            if not text:
                if col == "t":
                    raise TrajectoryFormatError(path, lineno, col, "time is empty")
                data[col].append(math.nan)
                continue
            try:
                value = float(text)
            except ValueError:
                raise TrajectoryFormatError(path, lineno, col, f"not a number: {text!r}") from None
            if math.isnan(value):
                if col == "t":
                    raise TrajectoryFormatError(path, lineno, col, "time is missing (NaN)")
                data[col].append(math.nan)  # a missing sample, as an empty cell
                continue
            if math.isinf(value):
                raise TrajectoryFormatError(
                    path, lineno, col, f"infinite: {text!r} (NaN or an empty cell = missing)"
                )
            if col == "load_share" and not 0.0 <= value <= 1.0:
                raise TrajectoryFormatError(path, lineno, col, f"expected 0..1, got {value}")
            if col == "gripper_closed" and value not in (0.0, 1.0):
                raise TrajectoryFormatError(path, lineno, col, f"expected 0 or 1, got {value}")
            data[col].append(value)

    def pts(prefix: str) -> np.ndarray:
        cols = [f"{prefix}_{a}" for a in "xyz"]
        if cols[0] not in data:
            return _nan_points(len(data["t"]))
        arr = np.array([data[c] for c in cols], dtype=float).T.reshape(-1, 3)
        # A point with only some coordinates is unusable: treat the whole point as missing.
        arr[np.isnan(arr).any(axis=1)] = np.nan
        return arr

    n = len(data["t"])
    return Trajectory(
        t=np.array(data["t"], dtype=float),
        giver_hand=pts("giver_hand"),
        receiver_hand=pts("receiver_hand"),
        giver_face=pts("giver_face"),
        gripper_closed=np.array(data.get("gripper_closed", [math.nan] * n), dtype=float),
        load_share=np.array(data.get("load_share", [math.nan] * n), dtype=float),
    )
