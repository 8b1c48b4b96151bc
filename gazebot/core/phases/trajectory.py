"""Tracked hand trajectories: arrays, the CSV they are written as, and conversion to/from
tracking frames.

:meth:`Trajectory.to_csv` writes ``t,giver_hand_x,giver_hand_y,giver_hand_z,receiver_hand_x,
receiver_hand_y,receiver_hand_z`` (s, m), and ``giver_face_x,giver_face_y,giver_face_z``,
``gripper_closed`` (0/1) and ``load_share`` (0..1) when known; an empty cell is a missing
sample. Reading it, and every other recording format, is :mod:`gazebot.io.recordings`'
(:func:`gazebot.io.recordings.csv_table.read_csv`).
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
        """Write the CSV that :func:`gazebot.io.recordings.csv_table.read_csv` reads (NaN ->
        empty cell)."""
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
