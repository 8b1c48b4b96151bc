"""The exact BIP filter: the extended Kalman filter on the stacked state ``[phi, phi_dot, w]``
with a full covariance (Campbell and Amor, CoRL 2017; IntPrim's mathematical notes eqs. 2-4).

gazebot's controller runs the ensemble filter (:mod:`gazebot.apps.bip.enbip`); this one is its
reference: the same model and update written as a dense Kalman filter, used by the benchmark as
the peer and by the tests to check the ensemble against.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from gazebot.apps.bip.enbip import FilterConfig
from gazebot.apps.bip.prior import BipPrior


class ExtendedBIP:
    """Mean ``mu`` and covariance ``sigma`` of the state, from the prior (eq. 5)."""

    def __init__(self, prior: BipPrior, config: FilterConfig | None = None) -> None:
        self.prior = prior
        self.config = cfg = config or FilterConfig()
        self.mu = prior.mean.copy()
        self.sigma = prior.cov.copy()
        obs = np.asarray(cfg.observed)
        self._obs = obs
        self._r = np.diag(prior.noise_var[obs])
        B = prior.n_basis
        self._obs_cols = 2 + obs[:, None] * B + np.arange(B)  # (m, B)

    def propagate(self, dt: float) -> None:
        """Eq. (2): ``mu <- G mu``, ``sigma <- G sigma G^T + Q``."""
        q = self.config.phase_noise**2 * np.array(
            [[dt**4 / 4.0, dt**3 / 3.0], [dt**3 / 3.0, dt**2]]
        )
        self.mu[0] += dt * self.mu[1]
        s = self.sigma
        # G = I + dt e_0 e_1^T: row 0 gains dt * row 1, then column 0 gains dt * column 1.
        s[0, :] += dt * s[1, :]
        s[:, 0] += dt * s[:, 1]
        s[:2, :2] += q

    def update(self, y: Sequence[float] | np.ndarray) -> None:
        """Eqs. (3)-(4): linearised observation of the observed degrees of freedom."""
        y = np.asarray(y, float)
        basis = self.prior.basis
        phi, dphi = basis.values(self.mu[0]), basis.derivative(self.mu[0])
        w = self.mu[self._obs_cols]  # (m, B)
        m, n = self._obs.size, self.mu.size
        h = np.zeros((m, n))
        h[:, 0] = w @ dphi
        rows = np.arange(m)[:, None]
        h[rows, self._obs_cols] = phi
        sh = self.sigma @ h.T  # (n, m)
        s = h @ sh + self._r
        gain = np.linalg.solve(s, sh.T).T
        self.mu += gain @ (y - w @ phi)
        self.sigma -= gain @ sh.T

    def step(self, y: Sequence[float] | np.ndarray, dt: float) -> None:
        self.propagate(dt)
        self.update(y)
