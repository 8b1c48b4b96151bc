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
    return eye_angles_of(v[0], v[1], v[2])  # math's functions take them as floats


def eye_angles_of(x: float, y: float, z: float) -> tuple[float, float]:
    """:func:`eye_angles` of ``(x, y, z)`` given as floats (the gaze controller's per-tick form)."""
    return math.atan2(y, x), math.atan2(-z, math.hypot(x, y))


def eye_direction(yaw: float, pitch: float) -> np.ndarray:
    """Unit line of sight (gaze frame) of eyes at ``(yaw, pitch)``."""
    cp = math.cos(pitch)
    return np.array([cp * math.cos(yaw), cp * math.sin(yaw), -math.sin(pitch)])


def angle_between(a: np.ndarray | Sequence[float], b: np.ndarray | Sequence[float]) -> float:
    """Angle (rad) between two non-zero 3-vectors, accurate for small and large angles."""
    return angle_of(float(a[0]), float(a[1]), float(a[2]), float(b[0]), float(b[1]), float(b[2]))


def angle_of(ax: float, ay: float, az: float, bx: float, by: float, bz: float) -> float:
    """:func:`angle_between` of ``(ax, ay, az)`` and ``(bx, by, bz)`` given as floats (the gaze
    controller's per-tick form: no conversions)."""
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    return math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), ax * bx + ay * by + az * bz)


@dataclass(frozen=True)
class DisplayEyes:
    """Eyes on a screen: a yaw/pitch range and a speed limit (rad, rad/s)."""

    yaw_range: tuple[float, float]
    pitch_range: tuple[float, float]
    velocity_limit: float

    def clip(self, yaw: float, pitch: float) -> tuple[float, float, bool]:
        """Clip to the eye range; the flag says whether anything was clipped."""
        # min(max(v, lo), hi) as comparisons (the same result, NaN included): this runs twice
        # per controller tick and once per loop tick.
        lo, hi = self.yaw_range
        y = lo if yaw < lo else yaw
        if y > hi:
            y = hi
        lo, hi = self.pitch_range
        p = lo if pitch < lo else pitch
        if p > hi:
            p = hi
        return y, p, (y != yaw or p != pitch)

    def look(self, v: np.ndarray | Sequence[float]) -> tuple[float, float, bool]:
        """Eye angles looking along ``v`` (gaze frame), clipped to the range, and the clip flag."""
        return self.clip(*eye_angles(v))

    def residual(self, yaw: float, pitch: float, v: np.ndarray | Sequence[float]) -> float:
        """Angle (rad) between the eyes' line of sight and ``v`` (gaze frame)."""
        # (float() on v: a float32 or float16 component would otherwise keep the products in
        # its own precision.)
        return residual_of(yaw, pitch, float(v[0]), float(v[1]), float(v[2]))


def residual_of(yaw: float, pitch: float, x: float, y: float, z: float) -> float:
    """Angle (rad) between the line of sight of eyes at ``(yaw, pitch)`` and ``(x, y, z)`` (gaze
    frame, floats): :meth:`DisplayEyes.residual`'s arithmetic, the gaze controller's per-tick
    form."""
    # eye_direction() as floats: numpy's per-call overhead would cost more than the arithmetic.
    cp = math.cos(pitch)
    return angle_of(cp * math.cos(yaw), cp * math.sin(yaw), -math.sin(pitch), x, y, z)
