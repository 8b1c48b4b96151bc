"""Two-handed reach-to-handover demonstrations: both wrists of a giver carrying an object of a
given grip width toward a receiver, and the receiver's two wrists reaching for it.

The seed trained its BIPs on its own bimanual human-human recordings (7.2, 7.4.2: "the Cartesian
trajectories of the giver's and receiver's left and right wrists, during 8 object handovers of one
pair of participants"); that dataset is not public, and no public two-handed handover recording
was reachable from here. :func:`generate` therefore synthesises demonstrations with human-like
timing and variability: minimum-jerk reaches (Flash and Hogan; :mod:`gazebot.apps.sim.motion`),
a per-demonstration reach duration, endpoint, lift, grip-axis yaw and grip width, the receiver
starting after a reaction delay, and motion-capture noise.

Frame: the robot (giver) base frame of every gazebot scene, m: x toward the receiver, z up; the
giver's left is +y. The grip width is the distance between the giver's wrists while they hold the
object (the seed's constraint: "maintain a fixed distance between its hands, equal to the grip
width of the object", 7.4.2), and is also a degree of freedom of its own, as in the seed ("We also
include the grip width of each object as a state variable").

A demonstration is stored as a CSV file: a ``t`` column (s) and one column per degree of freedom
(:data:`DOF_NAMES`, m).
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gazebot.core.minimum_jerk import minimum_jerk
from gazebot.io.recordings import RecordingError

WRISTS = ("giver_left", "giver_right", "receiver_left", "receiver_right")
DOF_NAMES: tuple[str, ...] = (
    *(f"{w}_{a}" for w in WRISTS for a in "xyz"),
    "grip_width",
)
GIVER_DOFS = tuple(range(0, 6))  # giver_left xyz, giver_right xyz
RECEIVER_DOFS = tuple(range(6, 12))
WIDTH_DOF = 12
RATE_HZ = 120.0  # the seed's motion-capture rate (OptiTrack, 7.3)
MIN_SAMPLES = 10


@dataclass(frozen=True)
class Demonstration:
    """One handover: ``t`` ``(T,)`` s from the giver's reach start, ``y`` ``(T, 13)`` m in
    :data:`DOF_NAMES` order."""

    t: np.ndarray
    y: np.ndarray
    name: str = ""

    @property
    def width(self) -> float:
        return float(np.median(self.y[:, WIDTH_DOF]))

    @property
    def phase(self) -> np.ndarray:
        """Linear phase ``t / T`` in [0, 1] (IntPrim's relative phase)."""
        return (self.t - self.t[0]) / (self.t[-1] - self.t[0])

    @property
    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])

    def giver_distance(self) -> np.ndarray:
        """Distance between the giver's wrists per sample (m)."""
        return wrist_distance(self.y[:, GIVER_DOFS])


def wrist_distance(giver: np.ndarray) -> np.ndarray:
    """``(..., 6)`` giver wrists (left xyz, right xyz) -> ``(...)`` distance between them (m)."""
    giver = np.asarray(giver, float)
    return np.linalg.norm(giver[..., 0:3] - giver[..., 3:6], axis=-1)


@dataclass(frozen=True)
class DemoGenerator:
    """Variability of the synthetic demonstrations (m, s, rad); every draw is per demonstration.

    Defaults: a ~1 s two-handed reach (human reach durations, seed 2.3.2) from in front of the
    giver's body to a handover location ~0.6 m out, the receiver ~1.05 m away starting after
    a reaction delay, boxes 0.22-0.42 m wide, 1.5 mm motion-capture noise.
    """

    width_range: tuple[float, float] = (0.22, 0.42)
    giver_start: tuple[float, float, float] = (0.30, 0.0, 0.95)
    giver_start_sd: float = 0.015
    handover: tuple[float, float, float] = (0.62, 0.0, 1.02)
    handover_sd: tuple[float, float, float] = (0.04, 0.05, 0.04)
    lift_mean: float = 0.05
    lift_sd: float = 0.015
    yaw_sd: float = np.radians(6.0)
    giver_duration: tuple[float, float] = (1.0, 0.1)  # mean, sd
    receiver_start: tuple[float, float, float] = (1.05, 0.20, 0.90)  # left hand at -y
    receiver_start_sd: float = 0.02
    receiver_reach_in: float = 0.10  # the receiver's wrists end this far beyond the object's centre
    reaction_delay: tuple[float, float] = (0.10, 0.25)  # uniform
    receiver_duration: tuple[float, float] = (0.85, 0.1)
    noise_sd: float = 0.0015
    rate_hz: float = RATE_HZ

    def draw(
        self, rng: np.random.Generator, width: float | None = None, name: str = ""
    ) -> Demonstration:
        """One demonstration; ``width`` fixes the grip width, else it is uniform in
        :attr:`width_range`."""
        w = float(rng.uniform(*self.width_range)) if width is None else float(width)
        if not (np.isfinite(w) and w > 0.0):
            raise ValueError(f"grip width must be a positive number of m, got {width}")
        t_giver = float(np.clip(rng.normal(*self.giver_duration), 0.7, 1.4))
        delay = float(rng.uniform(*self.reaction_delay))
        t_recv = float(np.clip(rng.normal(*self.receiver_duration), 0.6, 1.2))
        total = max(t_giver, delay + t_recv)
        t = np.arange(0.0, total + 0.5 / self.rate_hz, 1.0 / self.rate_hz)

        start = np.array(self.giver_start) + rng.normal(0.0, self.giver_start_sd, 3)
        goal = np.array(self.handover) + rng.normal(0.0, 1.0, 3) * np.array(self.handover_sd)
        yaw = rng.normal(0.0, self.yaw_sd)
        axis = np.array([-np.sin(yaw), np.cos(yaw), 0.0])  # giver's right -> left
        s = np.asarray(minimum_jerk(t / t_giver))[:, None]
        middle = start + (goal - start) * s
        middle[:, 2] += rng.normal(self.lift_mean, self.lift_sd) * np.sin(np.pi * s[:, 0])
        giver_left = middle + 0.5 * w * axis
        giver_right = middle - 0.5 * w * axis

        # The receiver faces the giver: their left hand is on the giver's right (-y).
        r0 = np.array(self.receiver_start)
        recv_left0 = r0 * [1, -1, 1] + rng.normal(0.0, self.receiver_start_sd, 3)
        recv_right0 = r0 + rng.normal(0.0, self.receiver_start_sd, 3)
        reach_in = np.array([self.receiver_reach_in, 0.0, -0.02])
        recv_left1 = goal + reach_in - 0.5 * w * axis
        recv_right1 = goal + reach_in + 0.5 * w * axis
        sr = np.asarray(minimum_jerk((t - delay) / t_recv))[:, None]
        recv_left = recv_left0 + (recv_left1 - recv_left0) * sr
        recv_right = recv_right0 + (recv_right1 - recv_right0) * sr

        wrists = np.hstack([giver_left, giver_right, recv_left, recv_right])
        wrists += rng.normal(0.0, self.noise_sd, wrists.shape)
        y = np.hstack([wrists, np.full((t.size, 1), w)])
        return Demonstration(t=t, y=y, name=name)

    def draw_many(
        self, n: int, seed: int, widths: Sequence[float] | None = None, prefix: str = "demo"
    ) -> list[Demonstration]:
        """``n`` demonstrations from ``seed``; ``widths`` (cycled) fixes their grip widths."""
        if n < 1:
            raise ValueError(f"need at least one demonstration, got {n}")
        rng = np.random.default_rng(seed)
        out = []
        for i in range(n):
            w = None if not widths else float(widths[i % len(widths)])
            out.append(self.draw(rng, w, name=f"{prefix}_{i:03d}"))
        return out


def save_demos(demos: Sequence[Demonstration], folder: str | Path) -> list[Path]:
    """Write each demonstration as ``folder/<name>.csv``; returns the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for i, d in enumerate(demos):
        path = folder / f"{d.name or f'demo_{i:03d}'}.csv"
        with path.open("w", newline="", encoding="utf-8") as fh:
            writer = csv.writer(fh)
            writer.writerow(["t", *DOF_NAMES])
            for tk, row in zip(d.t, d.y, strict=True):
                writer.writerow([f"{tk:.6f}", *(f"{v:.6f}" for v in row)])
        paths.append(path)
    return paths


def load_demo(path: str | Path) -> Demonstration:
    """Read one demonstration CSV; a malformed file is a :class:`RecordingError` naming it."""
    path = Path(path)
    try:
        with path.open(newline="", encoding="utf-8") as fh:
            rows = list(csv.reader(fh))
    except UnicodeDecodeError as exc:
        raise RecordingError(path, f"not a UTF-8 CSV file ({exc.reason})") from None
    if not rows:
        raise RecordingError(path, "empty file; expected a header t," + ",".join(DOF_NAMES))
    header = [h.strip() for h in rows[0]]
    missing = [c for c in ("t", *DOF_NAMES) if c not in header]
    if missing:
        raise RecordingError(path, f"missing column(s) {', '.join(missing)}")
    cols = [header.index(c) for c in ("t", *DOF_NAMES)]
    data = np.empty((len(rows) - 1, len(cols)))
    for i, row in enumerate(rows[1:], start=2):
        try:
            data[i - 2] = [float(row[c]) for c in cols]
        except (ValueError, IndexError):
            raise RecordingError(path, f"line {i}: expected {len(cols)} numbers") from None
    if len(data) < MIN_SAMPLES:
        raise RecordingError(path, f"{len(data)} samples; expected at least {MIN_SAMPLES}")
    if not np.all(np.isfinite(data)):
        raise RecordingError(path, "non-finite values; expected finite numbers (m, s)")
    if np.any(np.diff(data[:, 0]) <= 0.0):
        raise RecordingError(path, "column t: expected strictly increasing times (s)")
    if np.any(data[:, 1 + WIDTH_DOF] <= 0.0):
        raise RecordingError(path, "column grip_width: expected positive widths (m)")
    return Demonstration(t=data[:, 0] - data[0, 0], y=data[:, 1:], name=path.stem)


def load_demos(folder: str | Path) -> list[Demonstration]:
    """Every ``*.csv`` of ``folder`` (sorted by name), or the one file ``folder`` names."""
    folder = Path(folder)
    if folder.is_file():
        return [load_demo(folder)]
    if not folder.is_dir():
        raise RecordingError(folder, "no such file or folder of demonstration CSVs")
    paths = sorted(folder.glob("*.csv"))
    if not paths:
        raise RecordingError(folder, "no *.csv demonstrations in this folder")
    return [load_demo(p) for p in paths]
