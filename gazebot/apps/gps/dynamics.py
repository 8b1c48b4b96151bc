"""Time-varying linear-Gaussian dynamics (eq. 5.3) fitted by linear regression with a GMM prior.

p(x_t+1 | x_t, u_t) = N(f_x x_t + f_u u_t + f_c, F_t). At each t the joint Gaussian over
(x_t, u_t, x_t+1) is the MAP estimate from the few samples at t under a normal-inverse-Wishart
prior whose moments come from a Gaussian mixture fitted to every transition seen recently (all
conditions, all t), as in Levine et al.'s BADMM GPS; conditioning gives the linear model.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from sklearn.exceptions import ConvergenceWarning
from sklearn.mixture import GaussianMixture


@dataclass(frozen=True)
class LinearDynamics:
    """Fm (T-1, dX, dX+dU), fv (T-1, dX), cov (T-1, dX, dX); x0 mean and covariance."""

    Fm: np.ndarray
    fv: np.ndarray
    cov: np.ndarray
    x0_mu: np.ndarray
    x0_cov: np.ndarray


class GMMPrior:
    """A Gaussian mixture over transitions (x_t, u_t, x_t+1) (sklearn's EM)."""

    def __init__(self, clusters: int, seed: int = 0):
        self.clusters = clusters
        self.seed = seed
        self.gmm: GaussianMixture | None = None

    def fit(self, points: np.ndarray) -> None:
        k = max(1, min(self.clusters, points.shape[0] // 40))
        # k-means++ seeding and a few EM steps: the prior only needs rough moments. (At the same
        # 10 steps sklearn's k-means start is as fast: benchmarks/bench_gps.py, gmm_result.)
        self.gmm = GaussianMixture(k, covariance_type="full", reg_covar=1e-6,
                                   init_params="k-means++", random_state=self.seed, max_iter=10)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            self.gmm.fit(points)

    def moments(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Mean and covariance of the mixture, weighted by these points' responsibilities."""
        assert self.gmm is not None, "fit the prior first"
        w = self.gmm.predict_proba(points).mean(axis=0)
        mu = w @ self.gmm.means_
        diff = self.gmm.means_ - mu
        phi = np.einsum("k,kij->ij", w, self.gmm.covariances_) + np.einsum(
            "k,ki,kj->ij", w, diff, diff)
        return mu, phi


def transitions(X: np.ndarray, U: np.ndarray) -> np.ndarray:
    """Rows (x_t, u_t, x_t+1) from samples X (N, T, dX), U (N, T, dU)."""
    return np.concatenate([X[:, :-1], U[:, :-1], X[:, 1:]], axis=-1).reshape(
        -1, 2 * X.shape[-1] + U.shape[-1])


def fit_dynamics(X: np.ndarray, U: np.ndarray, prior: GMMPrior | None, strength: float,
                 reg: float = 1e-6) -> LinearDynamics:
    """Fit eq. 5.3 to one condition's samples X (N, T, dX), U (N, T, dU)."""
    n, horizon, dx = X.shape
    du = U.shape[-1]
    dxu = dx + du
    Fm = np.zeros((horizon - 1, dx, dxu))
    fv = np.zeros((horizon - 1, dx))
    cov = np.zeros((horizon - 1, dx, dx))
    for t in range(horizon - 1):
        pts = np.concatenate([X[:, t], U[:, t], X[:, t + 1]], axis=1)
        mun = pts.mean(axis=0)
        diff = pts - mun
        empsig = diff.T @ diff / n
        if prior is not None:
            mu0, phi = prior.moments(pts)
            m = n0 = strength
            sigma = (n * empsig + n0 * phi + (n * m) / (n + m) * np.outer(mun - mu0, mun - mu0)
                     ) / (n + n0)
        else:
            sigma = empsig
        sigma = 0.5 * (sigma + sigma.T) + reg * np.eye(sigma.shape[0])
        A = sigma[:dxu, :dxu]
        f = np.linalg.solve(A, sigma[:dxu, dxu:]).T
        Fm[t] = f
        fv[t] = mun[dxu:] - f @ mun[:dxu]
        c = sigma[dxu:, dxu:] - f @ A @ f.T
        cov[t] = 0.5 * (c + c.T)
    x0 = X[:, 0]
    x0_cov = np.diag(np.maximum(x0.var(axis=0), 1e-6))
    return LinearDynamics(Fm, fv, cov, x0.mean(axis=0), x0_cov)
