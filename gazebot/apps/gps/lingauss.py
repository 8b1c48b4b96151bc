"""Time-varying linear-Gaussian local controllers, eq. 5.2:
p_i(u_t | x_t) = N(K_t x_t + k_t, C_t)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LinearGaussian:
    """K (T, dU, dX), k (T, dU), cov (T, dU, dU)."""

    K: np.ndarray
    k: np.ndarray
    cov: np.ndarray

    @property
    def horizon(self) -> int:
        return self.K.shape[0]

    @property
    def chol(self) -> np.ndarray:
        return np.linalg.cholesky(self.cov)

    @property
    def precision(self) -> np.ndarray:
        return np.linalg.inv(self.cov)

    def mean(self, t: int, x: np.ndarray) -> np.ndarray:
        """The mean action K_t x + k_t (x may be a batch of states, shape (..., dX))."""
        return x @ self.K[t].T + self.k[t]

    def act(self, t: int, x: np.ndarray, noise: np.ndarray) -> np.ndarray:
        """A sample: mean plus chol(C_t) times a standard-normal ``noise`` vector."""
        return self.mean(t, x) + np.linalg.cholesky(self.cov[t]) @ noise


def pd_controller(x_home: np.ndarray, kp: np.ndarray, kd: np.ndarray, horizon: int, dx: int,
                  du: int, std: np.ndarray) -> LinearGaussian:
    """The initial local controller: a joint-space PD law holding the home posture (the first 7
    state entries are the joint angles, the next 7 their velocities) with exploration ``std``;
    the gripper channel (last action) pushes open with no feedback."""
    n = kp.shape[0]
    K = np.zeros((horizon, du, dx))
    K[:, np.arange(n), np.arange(n)] = -kp
    K[:, np.arange(n), n + np.arange(n)] = -kd
    k = np.zeros((horizon, du))
    k[:, :n] = kp * x_home[:n]
    cov = np.broadcast_to(np.diag(std**2), (horizon, du, du)).copy()
    return LinearGaussian(K, k, cov)
