"""Blinks for the robot's eyes: spontaneous at a natural rate with jitter, and with big gaze shifts.

People blink about 15-20 times a minute at irregular intervals, and a large gaze shift (a saccade
of more than about 20 degrees, often with a head turn) is usually accompanied by a blink. The model
draws the interval to the next spontaneous blink from a gamma distribution (mean ``60 / rate``,
never shorter than ``min_interval_s``) and starts a blink with probability ``shift_probability``
when the gaze moved more than ``shift_threshold_rad`` within about ``shift_window_s`` (so one big
jump and a quick run of per-frame steps count alike, while a slow pursuit does not).
The lid profile closes fast and opens slower, like a human blink (~0.3 s in all).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class BlinkConfig:
    """Blink timing (seconds) and the gaze-shift trigger (radians)."""

    rate_per_min: float = 17.0
    interval_shape: float = 3.0  # gamma shape of the intervals: higher = more regular
    min_interval_s: float = 0.8
    close_s: float = 0.08
    closed_s: float = 0.04
    open_s: float = 0.18
    shift_threshold_rad: float = math.radians(20.0)
    shift_probability: float = 0.9
    shift_window_s: float = 0.15

    def __post_init__(self) -> None:
        checks = {
            "rate_per_min": self.rate_per_min > 0,
            "interval_shape": self.interval_shape > 0,
            "min_interval_s": self.min_interval_s >= 0,
            "close_s": self.close_s > 0,
            "closed_s": self.closed_s >= 0,
            "open_s": self.open_s > 0,
            "shift_threshold_rad": self.shift_threshold_rad > 0,
            "shift_probability": 0 <= self.shift_probability <= 1,
            "shift_window_s": self.shift_window_s > 0,
        }
        for name, ok in checks.items():
            value = getattr(self, name)
            if not (math.isfinite(value) and ok):
                raise ValueError(f"BlinkConfig.{name} is out of range: {value!r}")
        if 60.0 / self.rate_per_min <= self.min_interval_s:
            raise ValueError("BlinkConfig: 60 / rate_per_min must exceed min_interval_s")

    @property
    def duration_s(self) -> float:
        """Length of one blink (close + closed + open)."""
        return self.close_s + self.closed_s + self.open_s


def _smoothstep(x: float) -> float:
    x = min(max(x, 0.0), 1.0)
    return x * x * (3.0 - 2.0 * x)


class BlinkModel:
    """``update(t, gaze_shift_rad) -> blink`` (0 open .. 1 closed); deterministic for a seed.

    ``t`` is the time (s, non-decreasing across calls); ``gaze_shift_rad`` is how far the gaze
    direction moved since the previous call (or the size of a shift starting now).
    """

    def __init__(self, seed: int = 0, config: BlinkConfig | None = None):
        self.seed = int(seed)
        self.config = config or BlinkConfig()
        self.reset()

    def reset(self) -> None:
        """Forget the time line (the next ``update`` starts a new one) and re-seed."""
        self._rng = np.random.default_rng(self.seed)
        self._t: float | None = None
        self._next = math.inf
        self._start = -math.inf
        self._acc = 0.0
        self._armed = True
        self.blinks = 0  # blinks started so far
        self.blink_times: list[float] = []

    def _interval(self) -> float:
        c = self.config
        mean_extra = 60.0 / c.rate_per_min - c.min_interval_s
        return c.min_interval_s + float(
            self._rng.gamma(c.interval_shape, mean_extra / c.interval_shape)
        )

    def _begin(self, t: float) -> None:
        self._start = t
        self.blinks += 1
        self.blink_times.append(t)
        self._next = t + self._interval()

    def value_at(self, t: float) -> float:
        """The lid closure of the current/last blink at time ``t`` (no state change)."""
        c = self.config
        tau = t - self._start
        if tau < 0 or tau >= c.duration_s:
            return 0.0
        if tau < c.close_s:
            return _smoothstep(tau / c.close_s)
        if tau < c.close_s + c.closed_s:
            return 1.0
        return 1.0 - _smoothstep((tau - c.close_s - c.closed_s) / c.open_s)

    def update(self, t: float, gaze_shift_rad: float = 0.0) -> float:
        """Advance to time ``t`` (s) after the gaze moved by ``gaze_shift_rad`` (a shift beyond
        pi counts as pi); return the blink.

        Raises ``ValueError`` for a non-finite ``t`` or shift, or a ``t`` earlier than the last one
        (call :meth:`reset` to start over).
        """
        t = float(t)
        shift = float(gaze_shift_rad)
        if not math.isfinite(t):
            raise ValueError(f"t must be finite, got {t}")
        if not math.isfinite(shift):
            raise ValueError(f"gaze_shift_rad must be finite, got {shift}")
        c = self.config
        last = self._t
        if last is None:
            self._t = last = t
            self._next = t + self._interval()
        if t < last - 1e-9:
            raise ValueError(f"t went backwards ({t} < {last}); call reset() to restart")
        dt = max(t - last, 0.0)
        self._t = t
        # The decayed sum of gaze shifts. No shift is more than a half turn: a larger value
        # counts as one, so the sum stays finite and decays (inf would decay to NaN and disarm
        # the shift rule for good).
        acc = self._acc * math.exp(-dt / c.shift_window_s) + min(abs(shift), math.pi)
        self._acc = acc
        if acc < 0.5 * c.shift_threshold_rad:
            self._armed = True
        in_blink = t - self._start < c.duration_s
        if self._armed and acc >= c.shift_threshold_rad:
            self._armed = False  # one decision per shift
            if self._rng.random() < c.shift_probability and not in_blink:
                self._begin(t)
                in_blink = True
        if not in_blink and t >= self._next:
            self._begin(t)
        return self.value_at(t)
