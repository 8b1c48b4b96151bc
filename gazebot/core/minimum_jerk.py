"""The minimum-jerk profile: the bell-shaped speed profile of human reaches (seed 2.3.2, Flash
and Hogan 1985) and of gaze shifts (the iCub gaze controller, Roncone et al. 2016).

A rest-to-rest move from 0 to 1 over normalised time ``s = (t - t0) / T`` in ``[0, 1]`` follows

    x(s) = 10 s^3 - 15 s^4 + 6 s^5 = s^3 (10 + s (-15 + 6 s)),

with rate ``dx/ds = 30 s^2 (1 - s)^2``: zero velocity and acceleration at both ends, the peak
``dx/ds = 1.875`` at ``s = 1/2``. So a move of amplitude ``A`` over ``T`` seconds peaks at
``PEAK_RATE * A / T``.

Both functions take a float or an array (element-wise) and clip ``s`` to ``[0, 1]``: before the
move the profile holds 0, after it 1.

The one definition of the profile for the whole package: phase rules and synthetic handovers
(``core.phases``), gaze shifts (``core.kinematics``) and the simulator's actors
(``apps.sim.motion``). It lives at the top of ``core`` so the phase code can use it without
loading the robot kinematics (Pinocchio).
"""

from __future__ import annotations

from typing import TypeVar, overload

import numpy as np

PEAK_RATE = 1.875
"""The largest rate ``dx/ds`` of the profile (at ``s = 1/2``)."""

_Array = TypeVar("_Array", bound=np.ndarray)


@overload
def _clip_unit(s: float) -> float: ...
@overload
def _clip_unit(s: _Array) -> _Array: ...
def _clip_unit(s: float | np.ndarray) -> float | np.ndarray:
    """``s`` clipped to ``[0, 1]`` (a NaN stays NaN)."""
    if isinstance(s, np.ndarray):
        return np.clip(s, 0.0, 1.0)
    return min(max(float(s), 0.0), 1.0)


@overload
def minimum_jerk(s: float) -> float: ...
@overload
def minimum_jerk(s: _Array) -> _Array: ...
def minimum_jerk(s: float | np.ndarray) -> float | np.ndarray:
    """Position ``x(s) = s^3 (10 + s (-15 + 6 s))`` of the minimum-jerk move 0 -> 1 at
    normalised time ``s`` (clipped to ``[0, 1]``)."""
    s = _clip_unit(s)
    return s * s * s * (10.0 + s * (-15.0 + 6.0 * s))


@overload
def minimum_jerk_rate(s: float) -> float: ...
@overload
def minimum_jerk_rate(s: _Array) -> _Array: ...
def minimum_jerk_rate(s: float | np.ndarray) -> float | np.ndarray:
    """Rate ``dx/ds = 30 s^2 (1 - s)^2`` of :func:`minimum_jerk` (``s`` clipped to ``[0, 1]``;
    divide by the duration for a velocity)."""
    s = _clip_unit(s)
    return 30.0 * s**2 * (1.0 - s) ** 2
