"""Minimum-jerk point-to-point motion: the bell-shaped speed profile of human reaches (seed 2.3.2,
Flash and Hogan) and of the seed's MCJ robot controller (section 3.2.1)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def min_jerk_phase(tau: float | np.ndarray) -> float | np.ndarray:
    """Normalized position s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5, tau clipped to [0, 1]."""
    tau = np.clip(tau, 0.0, 1.0)
    return tau**3 * (10.0 + tau * (-15.0 + 6.0 * tau))


def min_jerk_rate(tau: float | np.ndarray) -> float | np.ndarray:
    """ds/dtau = 30 tau^2 (1 - tau)^2: zero at both ends, peak 1.875 at tau = 0.5."""
    tau = np.clip(tau, 0.0, 1.0)
    return 30.0 * tau**2 * (1.0 - tau) ** 2


PEAK_RATE = 1.875  # max of min_jerk_rate; peak speed = PEAK_RATE * distance / duration


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
        s = min_jerk_phase(self.tau(t))
        return self.start + (self.goal - self.start) * s

    def velocity(self, t: float) -> np.ndarray:
        ds = min_jerk_rate(self.tau(t)) / self.duration
        return (self.goal - self.start) * ds

    def done(self, t: float) -> bool:
        return t >= self.t_end
