"""Minimum-jerk gaze shifts: the timing model of the neck and the eyes.

As in the iCub gaze controller (Roncone et al., RSS 2016), the neck and the eyes each follow a
minimum-jerk trajectory with their own duration: the eyes are fast (about 0.1-0.25 s) and lead,
the neck is slower (about 0.5-0.8 s) and catches up while the eyes counter-rotate. Durations
stretch when a joint's velocity limit would be exceeded (peak speed of a minimum-jerk move is
1.875 x amplitude / duration).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

# Peak velocity of a rest-to-rest minimum-jerk move = MINJERK_PEAK * amplitude / duration.
MINJERK_PEAK = 1.875


class GazeShiftConfig(BaseModel):
    """Timing of gaze shifts (seconds; the threshold in degrees, a YAML surface).

    Attributes:
        eye_duration_s: Duration of an eye saccade (minimum jerk).
        neck_duration_s: Duration of a neck movement for a new target (minimum jerk).
        tracking_duration_s: Shortest re-plan horizon of the neck while following a moving target.
        saccade_threshold_deg: A target direction change larger than this starts a new gaze shift
            (eyes saccade, neck re-plans with its full duration); smaller changes are tracked.
        velocity_margin: Durations are chosen so that the planned peak speed is at most this
            fraction of the velocity limit (the hard limit is enforced anyway).
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    eye_duration_s: float = Field(0.15, ge=0.05, le=0.5)
    neck_duration_s: float = Field(0.65, ge=0.2, le=3.0)
    tracking_duration_s: float = Field(0.3, ge=0.05, le=3.0)
    saccade_threshold_deg: float = Field(3.0, gt=0.0, le=90.0)
    velocity_margin: float = Field(0.9, gt=0.1, le=1.0)

    @model_validator(mode="after")
    def _eyes_faster_than_neck(self) -> GazeShiftConfig:
        if self.eye_duration_s >= self.neck_duration_s:
            raise ValueError("eye_duration_s shorter than neck_duration_s (the eyes lead)")
        return self

    @property
    def saccade_threshold(self) -> float:
        """The saccade threshold in rad."""
        return math.radians(self.saccade_threshold_deg)


def min_jerk(tau: float) -> float:
    """Normalized minimum-jerk position ``10 s^3 - 15 s^4 + 6 s^5``, ``s = clip(tau, 0, 1)``."""
    s = min(max(tau, 0.0), 1.0)
    return s * s * s * (10.0 + s * (-15.0 + 6.0 * s))


def min_jerk_duration(
    amplitude: np.ndarray | float,
    nominal: float,
    velocity_limit: np.ndarray | float,
    margin: float = 0.9,
) -> float:
    """Shortest duration >= ``nominal`` whose rest-to-rest minimum-jerk peak speed stays within
    ``margin * velocity_limit`` for every joint."""
    amp = np.abs(np.asarray(amplitude, dtype=float))
    vmax = np.asarray(velocity_limit, dtype=float) * margin
    need = float(np.max(MINJERK_PEAK * amp / vmax)) if amp.size else 0.0
    return max(nominal, need)


class Trajectory(ABC):
    """A joint-space trajectory (vector valued) over absolute time."""

    @property
    @abstractmethod
    def end_time(self) -> float:
        """Time at which the trajectory reaches its goal and stays there."""

    @abstractmethod
    def evaluate(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity and acceleration at time ``t`` (clamped to the trajectory's span)."""

    def position(self, t: float) -> np.ndarray:
        """Position at time ``t``."""
        return self.evaluate(t)[0]


class MinJerkTrajectory(Trajectory):
    """Quintic from ``(p0, v0, a0)`` at ``t0`` to ``(p1, 0, 0)`` at ``t0 + duration``.

    With ``v0 = a0 = 0`` this is the classic minimum-jerk profile; non-zero initial velocity and
    acceleration let a moving neck re-plan toward a new goal without a jump in velocity or
    acceleration (the minimum-jerk solution for those boundary conditions).
    """

    def __init__(
        self,
        t0: float,
        duration: float,
        p0: np.ndarray,
        p1: np.ndarray,
        v0: np.ndarray | None = None,
        a0: np.ndarray | None = None,
    ) -> None:
        if not duration > 0.0:
            raise ValueError(f"duration must be positive, got {duration}")
        p0 = np.asarray(p0, dtype=float)
        p1 = np.asarray(p1, dtype=float)
        v0 = np.zeros_like(p0) if v0 is None else np.asarray(v0, dtype=float)
        a0 = np.zeros_like(p0) if a0 is None else np.asarray(a0, dtype=float)
        T = float(duration)
        d = p1 - p0
        self.t0 = float(t0)
        self.duration = T
        self.goal = p1.copy()
        self._c = np.array(
            [
                p0,
                v0,
                0.5 * a0,
                (20.0 * d - 12.0 * v0 * T - 3.0 * a0 * T * T) / (2.0 * T**3),
                (-30.0 * d + 16.0 * v0 * T + 3.0 * a0 * T * T) / (2.0 * T**4),
                (12.0 * d - 6.0 * v0 * T - a0 * T * T) / (2.0 * T**5),
            ]
        )

    @property
    def end_time(self) -> float:
        return self.t0 + self.duration

    def evaluate(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = min(max(t - self.t0, 0.0), self.duration)
        c = self._c
        pos = c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * (c[4] + s * c[5]))))
        vel = c[1] + s * (2 * c[2] + s * (3 * c[3] + s * (4 * c[4] + s * 5 * c[5])))
        acc = 2 * c[2] + s * (6 * c[3] + s * (12 * c[4] + s * 20 * c[5]))
        if s >= self.duration:
            # Exactly at rest on the goal afterwards (no round-off creep).
            return self.goal.copy(), np.zeros_like(pos), np.zeros_like(pos)
        return pos, vel, acc
