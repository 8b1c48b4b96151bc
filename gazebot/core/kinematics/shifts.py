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
from collections.abc import Sequence

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from gazebot.core.minimum_jerk import PEAK_RATE


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
    need = float(np.max(PEAK_RATE * amp / vmax)) if amp.size else 0.0
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


# Position, velocity and acceleration of every joint as plain floats.
Sample = tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]


def _floats(x: np.ndarray | Sequence[float]) -> list[float]:
    """A flat list of Python floats."""
    if isinstance(x, np.ndarray):
        return x.astype(float, copy=False).reshape(-1).tolist()
    if type(x) is list or type(x) is tuple:
        return list(map(float, x))
    return np.asarray(x, dtype=float).reshape(-1).tolist()


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
        p0: np.ndarray | Sequence[float],
        p1: np.ndarray | Sequence[float],
        v0: np.ndarray | Sequence[float] | None = None,
        a0: np.ndarray | Sequence[float] | None = None,
    ) -> None:
        if not duration > 0.0:
            raise ValueError(f"duration must be positive, got {duration}")
        # Plain floats on purpose: the gaze controller re-plans every tick for 1-4 joints, where
        # numpy's per-call overhead would cost more than the arithmetic.
        start = _floats(p0)
        n = len(start)
        self._plan(
            float(t0),
            float(duration),
            start,
            _floats(p1),
            [0.0] * n if v0 is None else _floats(v0),
            [0.0] * n if a0 is None else _floats(a0),
        )

    @classmethod
    def of_floats(
        cls,
        t0: float,
        duration: float,
        p0: Sequence[float],
        p1: Sequence[float],
        v0: Sequence[float],
        a0: Sequence[float],
    ) -> MinJerkTrajectory:
        """The trajectory ``MinJerkTrajectory(t0, duration, p0, p1, v0, a0)`` gives, from values
        that already are Python floats (``duration > 0``, sequences of equal length): the gaze
        controller re-plans every tick and skips the conversions (a duration from the config
        may be an int)."""
        traj = cls.__new__(cls)
        traj._plan(t0, float(duration), p0, p1, v0, a0)
        return traj

    def _plan(
        self,
        t0: float,
        T: float,
        start: Sequence[float],
        goal: Sequence[float],
        vel: Sequence[float],
        acc: Sequence[float],
    ) -> None:
        """The quintic's coefficients per joint from floats."""
        n = len(start)
        if not len(goal) == len(vel) == len(acc) == n:
            raise ValueError("p0, p1, v0 and a0 must have the same length")
        k3, k4, k5 = 0.5 / T**3, 0.5 / T**4, 0.5 / T**5
        self.t0 = t0
        self.duration = T
        self._goal = tuple(goal)
        coeffs = []
        for p, g, v, a in zip(start, goal, vel, acc, strict=True):
            d, vt, at2 = g - p, v * T, a * T * T
            coeffs.append(
                (
                    p,
                    v,
                    0.5 * a,
                    (20.0 * d - 12.0 * vt - 3.0 * at2) * k3,
                    (-30.0 * d + 16.0 * vt + 3.0 * at2) * k4,
                    (12.0 * d - 6.0 * vt - at2) * k5,
                )
            )
        self._coeffs = coeffs
        self._last: tuple[float, Sample] | None = None

    @property
    def goal(self) -> np.ndarray:
        """The end position."""
        return np.array(self._goal)

    @property
    def end_time(self) -> float:
        return self.t0 + self.duration

    def sample(self, t: float) -> Sample:
        """:meth:`evaluate` as tuples of floats (position, velocity, acceleration)."""
        last = self._last
        if last is not None and last[0] == t:
            # A plan asked twice for the same time (e.g. a re-plan's start state) is computed once.
            return last[1]
        s = min(max(t - self.t0, 0.0), self.duration)
        if s >= self.duration:
            # Exactly at rest on the goal afterwards (no round-off creep).
            zeros = (0.0,) * len(self._goal)
            out: Sample = (self._goal, zeros, zeros)
        else:
            pos, vel, acc = [], [], []
            for c0, c1, c2, c3, c4, c5 in self._coeffs:
                pos.append(c0 + s * (c1 + s * (c2 + s * (c3 + s * (c4 + s * c5)))))
                vel.append(c1 + s * (2 * c2 + s * (3 * c3 + s * (4 * c4 + s * 5 * c5))))
                acc.append(2 * c2 + s * (6 * c3 + s * (12 * c4 + s * 20 * c5)))
            out = (tuple(pos), tuple(vel), tuple(acc))
        self._last = (t, out)
        return out

    def sample_position(self, t: float) -> list[float]:
        """The position of :meth:`sample` alone, as a list of floats (the gaze controller's
        command each tick; velocity and acceleration are needed only to re-plan)."""
        # min(max(t - t0, 0), duration) as comparisons (the same float, NaN and -0.0
        # included): this runs every tick the neck moves.
        s = t - self.t0
        if 0.0 > s:
            s = 0.0
        duration = self.duration
        if duration < s:
            s = duration
        if s >= duration:
            return list(self._goal)
        return [
            c0 + s * (c1 + s * (c2 + s * (c3 + s * (c4 + s * c5))))
            for c0, c1, c2, c3, c4, c5 in self._coeffs
        ]

    def evaluate(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        pos, vel, acc = self.sample(t)
        return np.array(pos), np.array(vel), np.array(acc)
