"""Simulated motion capture: exact points plus optional Gaussian noise and dropped samples."""

from __future__ import annotations

import numpy as np

from gazebot.apps.sim.scene_config import TrackingNoiseConfig


class TrackingNoise:
    """Adds isotropic noise (``noise_m`` sd per axis) and drops each point with ``dropout_rate``
    (all-NaN, like a marker the cameras lost)."""

    def __init__(self, config: TrackingNoiseConfig, rng: np.random.Generator) -> None:
        self.config = config
        self.rng = rng

    @property
    def active(self) -> bool:
        return self.config.noise_m > 0.0 or self.config.dropout_rate > 0.0

    def apply(self, point: np.ndarray) -> np.ndarray:
        out = np.asarray(point, float).copy()
        if self.config.noise_m > 0.0:
            out += self.rng.normal(0.0, self.config.noise_m, 3)
        if self.config.dropout_rate > 0.0 and self.rng.random() < self.config.dropout_rate:
            out[:] = np.nan
        return out
