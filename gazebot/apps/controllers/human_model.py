"""The seed's human-motion prediction for STL synthesis (section 4.4.1, eq. 4.5): a linear
dynamical system ``p_dot = A p`` fitted by least squares to the hand's recent positions, then
``p_h(t_0 + t) = p_h(t_0) + (t delta_t) A p_h(t_0)`` over the horizon."""

from __future__ import annotations

from collections import deque

import numpy as np


class LinearHandModel:
    """Keeps the last ``history`` hand samples (one per control step ``dt``) and predicts.

    Args:
        dt: Sampling interval delta_t (s).
        history: Samples in the least-squares window (at least 2).
    """

    def __init__(self, dt: float, history: int = 5) -> None:
        if history < 2:
            raise ValueError("history must be at least 2 samples")
        self.dt = float(dt)
        self._samples: deque[np.ndarray] = deque(maxlen=int(history))

    def reset(self) -> None:
        self._samples.clear()

    def observe(self, hand: np.ndarray) -> None:
        """Add the hand position of this control step (base frame, m)."""
        self._samples.append(np.asarray(hand, float).copy())

    def fit(self) -> np.ndarray:
        """``A`` (3, 3) minimizing ``sum ||(p_{k+1} - p_k)/dt - A p_k||^2`` (least squares, minimum
        norm when under-determined); zero with fewer than two samples (a still hand)."""
        if len(self._samples) < 2:
            return np.zeros((3, 3))
        P = np.array(self._samples)
        Pdot = np.diff(P, axis=0) / self.dt
        # Pdot ~ P[:-1] @ A.T
        At, *_ = np.linalg.lstsq(P[:-1], Pdot, rcond=None)
        return At.T

    def predict(self, steps: int) -> np.ndarray:
        """Predicted hand at ``t_0 + j dt``, ``j = 0..steps`` (eq. 4.5): shape (steps + 1, 3)."""
        if not self._samples:
            raise ValueError("no hand observed yet")
        p0 = self._samples[-1]
        v = self.fit() @ p0
        j = np.arange(steps + 1, dtype=float)[:, None]
        return p0 + j * self.dt * v
