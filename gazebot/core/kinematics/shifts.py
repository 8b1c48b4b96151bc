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


# c3, c4, c5 of the quintic: _HIGH_ORDER @ (d, v0 T, a0 T^2), each divided by 2 T^k.
_HIGH_ORDER = np.array([[20.0, -12.0, -3.0], [-30.0, 16.0, 3.0], [12.0, -6.0, -1.0]])
_HIGH_ORDER_SCALE = 0.5
_HIGH_POWERS = np.array([[3.0], [4.0], [5.0]])
for _constant in (_HIGH_ORDER, _HIGH_POWERS):
    _constant.flags.writeable = False


def _joint_vector(x: np.ndarray | Sequence[float] | None, n: int, name: str) -> np.ndarray:
    """``x`` as a float vector of ``n`` values (``None``: zeros).

    Raises:
        ValueError: ``x`` has another length.
    """
    if x is None:
        return np.zeros(n)
    v = np.asarray(x, dtype=float).reshape(-1)
    if v.shape != (n,):
        raise ValueError(f"p0, p1, v0 and a0 must have the same length ({name}: {v.size} != {n})")
    return v


class MinJerkTrajectory(Trajectory):
    """Quintic from ``(p0, v0, a0)`` at ``t0`` to ``(p1, 0, 0)`` at ``t0 + duration``.

    With ``v0 = a0 = 0`` this is the classic minimum-jerk profile
    (:func:`gazebot.core.minimum_jerk.minimum_jerk`); non-zero initial velocity and acceleration
    let a moving neck re-plan toward a new goal without a jump in velocity or acceleration (the
    minimum-jerk solution for those boundary conditions). Per joint, with ``d = p1 - p0`` and
    ``s = t - t0`` in ``[0, T]``:

        p(s) = p0 + v0 s + a0/2 s^2 + c3 s^3 + c4 s^4 + c5 s^5,
        c3 = (20 d - 12 v0 T - 3 a0 T^2) / (2 T^3),
        c4 = (-30 d + 16 v0 T + 3 a0 T^2) / (2 T^4),
        c5 = (12 d - 6 v0 T - a0 T^2) / (2 T^5).
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
        start = np.asarray(p0, dtype=float).reshape(-1)
        n = start.size
        goal = _joint_vector(p1, n, "p1")
        vel = _joint_vector(v0, n, "v0")
        acc = _joint_vector(a0, n, "a0")
        T = float(duration)
        self.t0 = float(t0)
        self.duration = T
        self._goal = goal
        # Rows: the coefficients of s^0 .. s^5, one column per joint (see the class docstring).
        boundary = np.array([goal - start, vel * T, acc * T * T])
        self._coeffs = np.vstack(
            [start, vel, 0.5 * acc, (_HIGH_ORDER @ boundary) * _HIGH_ORDER_SCALE / T**_HIGH_POWERS]
        )

    @property
    def goal(self) -> np.ndarray:
        """The end position."""
        return self._goal.copy()

    @property
    def end_time(self) -> float:
        """When the motion ends (s): ``t0 + duration``."""
        return self.t0 + self.duration

    def evaluate(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity and acceleration at time ``t``, clamped to the motion (before ``t0``
        its start, after its end at rest on the goal)."""
        s = min(max(t - self.t0, 0.0), self.duration)
        if s >= self.duration:
            # Exactly at rest on the goal afterwards (no round-off creep).
            zeros = np.zeros_like(self._goal)
            return self._goal.copy(), zeros, zeros.copy()
        pos, vel, acc = _power_basis(s) @ self._coeffs
        return pos, vel, acc

    def position(self, t: float) -> np.ndarray:
        """Position at time ``t``, clamped to the motion (before ``t0`` its start, after its end
        the goal)."""
        s = min(max(t - self.t0, 0.0), self.duration)
        if s >= self.duration:
            return self._goal.copy()
        return _power_basis(s)[0] @ self._coeffs


def _power_basis(s: float) -> np.ndarray:
    """Rows: ``(1, s, ..., s^5)`` and its first and second derivatives in ``s``, so that the
    quintic's coefficient rows ``c`` give position, velocity and acceleration as
    ``_power_basis(s) @ c``."""
    s2 = s * s
    s3 = s2 * s
    s4 = s3 * s
    return np.array(
        [
            [1.0, s, s2, s3, s4, s4 * s],
            [0.0, 1.0, 2.0 * s, 3.0 * s2, 4.0 * s3, 5.0 * s4],
            [0.0, 0.0, 2.0, 6.0 * s, 12.0 * s2, 20.0 * s3],
        ]
    )
