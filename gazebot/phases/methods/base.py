"""The base class of a phase method."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from gazebot.phases.config import PhaseConfig
from gazebot.phases.segment import Segment
from gazebot.phases.trajectory import Trajectory


class Segmenter(ABC):
    """Splits a recording into reach, transfer and retreat segments per handover.

    Attributes:
        config: The settings (``config.method`` names the concrete class).
    """

    name: str = ""

    def __init__(self, config: PhaseConfig) -> None:
        self.config = config

    @abstractmethod
    def segment_sorted(self, trajectory: Trajectory, partial: bool = False) -> list[Segment]:
        """Segments of a trajectory already sorted by time with unique times.

        ``partial``: the data are the samples seen so far by an online detector; a boundary the
        data do not yet show must not be guessed (the phase stays open).
        """

    def segment(self, trajectory: Trajectory) -> list[Segment]:
        """Segments of a whole recording (sorted first, see :meth:`Trajectory.cleaned`)."""
        traj, _, _ = trajectory.cleaned()
        return self.segment_sorted(traj)


def central_speed(t: np.ndarray, p: np.ndarray, half: float) -> np.ndarray:
    """``|p(t + half) - p(t - half)| / (2 half)`` at every sample time, ``p`` linearly
    interpolated between its valid samples (NaN where ``t +- half`` leaves them)."""
    ok = np.isfinite(p).all(axis=1)
    out = np.full(t.shape[0], np.nan)
    if np.count_nonzero(ok) < 2:
        return out
    tv, pv = t[ok], p[ok]
    lo, hi = t - half, t + half
    inside = (lo >= tv[0] - 1e-9) & (hi <= tv[-1] + 1e-9)
    a = np.stack([np.interp(lo, tv, pv[:, k]) for k in range(3)], axis=1)
    b = np.stack([np.interp(hi, tv, pv[:, k]) for k in range(3)], axis=1)
    out[inside] = np.linalg.norm(b - a, axis=1)[inside] / (2.0 * half)
    return out
