"""Eyes drawn on the head display: yaw/pitch from a direction in the gaze frame, and back.

Convention (gaze frame: +x line of sight, +y robot's left, +z display up): yaw is about +z
(positive = toward the robot's left), pitch about +y (positive = looking down). The eye direction
for ``(yaw, pitch)`` is ``Rz(yaw) Ry(pitch) x = (cos p cos y, cos p sin y, -sin p)``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


def eye_angles(v: np.ndarray | Sequence[float]) -> tuple[float, float]:
    """Yaw and pitch (rad) that point the eyes along ``v`` (gaze frame, any length > 0)."""
    x, y, z = map(float, v)
    return math.atan2(y, x), math.atan2(-z, math.hypot(x, y))


def eye_direction(yaw: float, pitch: float) -> np.ndarray:
    """Unit line of sight (gaze frame) of eyes at ``(yaw, pitch)``."""
    return np.array(_direction(yaw, pitch))


def _direction(yaw: float, pitch: float) -> tuple[float, float, float]:
    """:func:`eye_direction` as a tuple."""
    cp = math.cos(pitch)
    return cp * math.cos(yaw), cp * math.sin(yaw), -math.sin(pitch)


def angle_between(a: np.ndarray | Sequence[float], b: np.ndarray | Sequence[float]) -> float:
    """Angle (rad) between two non-zero 3-vectors, accurate for small and large angles
    (``atan2(|a x b|, a . b)``; computed in double precision whatever the input's)."""
    ax, ay, az = map(float, a)
    bx, by, bz = map(float, b)
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    return math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), ax * bx + ay * by + az * bz)


@dataclass(frozen=True)
class DisplayEyes:
    """Eyes on a screen: a yaw/pitch range and a speed limit (rad, rad/s)."""

    yaw_range: tuple[float, float]
    pitch_range: tuple[float, float]
    velocity_limit: float

    def clip(self, yaw: float, pitch: float) -> tuple[float, float, bool]:
        """Clip to the eye range; the flag says whether anything was clipped (a NaN stays
        NaN)."""
        y = min(max(yaw, self.yaw_range[0]), self.yaw_range[1])
        p = min(max(pitch, self.pitch_range[0]), self.pitch_range[1])
        return y, p, (y != yaw or p != pitch)

    def look(self, v: np.ndarray | Sequence[float]) -> tuple[float, float, bool]:
        """Eye angles looking along ``v`` (gaze frame), clipped to the range, and the clip flag."""
        return self.clip(*eye_angles(v))

    def residual(self, yaw: float, pitch: float, v: np.ndarray | Sequence[float]) -> float:
        """Angle (rad) between the eyes' line of sight and ``v`` (gaze frame)."""
        return angle_between(_direction(yaw, pitch), v)
