"""Minimum-jerk point-to-point motion: the bell-shaped speed profile of human reaches (seed 2.3.2,
Flash and Hogan) and of the seed's MCJ robot controller (section 3.2.1)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gazebot.core.minimum_jerk import PEAK_RATE, minimum_jerk, minimum_jerk_rate

__all__ = ["PEAK_RATE", "MinJerkSegment"]


@dataclass(frozen=True)
class MinJerkSegment:
    """A minimum-jerk move from ``start`` to ``goal`` (any same-shape arrays) over
    ``[t0, t0 + duration]``; holds the end points outside that interval."""

    start: np.ndarray
    goal: np.ndarray
    t0: float
    duration: float

    def __post_init__(self) -> None:
        if not np.isfinite(self.duration) or self.duration <= 0.0:
            raise ValueError(
                f"minimum-jerk duration must be a positive number, got {self.duration}"
            )

    @property
    def t_end(self) -> float:
        return self.t0 + self.duration

    def tau(self, t: float) -> float:
        return float(np.clip((t - self.t0) / self.duration, 0.0, 1.0))

    def position(self, t: float) -> np.ndarray:
        s = minimum_jerk(self.tau(t))
        return self.start + (self.goal - self.start) * s

    def velocity(self, t: float) -> np.ndarray:
        ds = minimum_jerk_rate(self.tau(t)) / self.duration
        return (self.goal - self.start) * ds

    def done(self, t: float) -> bool:
        return t >= self.t_end
