"""The reach cost of eq. 5.11 and its quadratic expansion for LQG.

c_reach = ||p_r - p_h||^2 + ln(||p_r - p_h||^2 + alpha_reach), plus a small action cost w_u ||u||^2
(ours: the seed's cost has none, but LQG needs a positive-definite action Hessian).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ReachCost:
    """Eq. 5.11 on the gap d = S x (gripper minus hand), and the action weights ``w_u`` (dU,)."""

    selector: np.ndarray  # (3, dX)
    alpha: float
    w_u: np.ndarray

    def reach(self, X: np.ndarray) -> np.ndarray:
        """c_reach of eq. 5.11 for states X (..., dX)."""
        s = np.sum((X @ self.selector.T) ** 2, axis=-1)
        return s + np.log(s + self.alpha)

    def total(self, X: np.ndarray, U: np.ndarray) -> np.ndarray:
        """Per-step cost for states (..., dX) and actions (..., dU)."""
        return self.reach(X) + np.sum(self.w_u * U**2, axis=-1)

    def expand(self, X: np.ndarray, U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Quadratic model c(xu) ~ 1/2 xu' Cm xu + cv' xu + const, expanded at each sample
        (X (N, T, dX), U (N, T, dU)) and averaged over samples: Cm (T, n, n), cv (T, n).

        The log term's curvature along d is negative away from the target; we keep only its
        positive part (a Gauss-Newton-like choice) so the LQG subproblem stays well posed.
        """
        S = self.selector
        dx, du = S.shape[1], U.shape[-1]
        d = X @ S.T  # (N, T, 3)
        s = np.sum(d**2, axis=-1)[..., None]  # (N, T, 1)
        g = 1.0 + 1.0 / (s + self.alpha)  # d c / d s
        grad_d = 2.0 * g * d
        along = 2.0 * g[..., 0] - 4.0 * s[..., 0] / (s[..., 0] + self.alpha) ** 2
        unit = d / np.sqrt(np.maximum(s, 1e-12))
        eye = np.eye(3)
        hess_d = (2.0 * g[..., None] * eye
                  + (np.maximum(along, 0.0) - 2.0 * g[..., 0])[..., None, None]
                  * unit[..., :, None] * unit[..., None, :])
        lx = grad_d @ S
        lxx = np.einsum("ai,ntab,bj->ntij", S, hess_d, S)
        lu = 2.0 * self.w_u * U
        n = dx + du
        Cm = np.zeros(X.shape[:2] + (n, n))
        Cm[..., :dx, :dx] = lxx
        Cm[..., dx:, dx:] = np.diag(2.0 * self.w_u)
        xu = np.concatenate([X, U], axis=-1)
        cv = np.concatenate([lx, lu], axis=-1) - np.einsum("ntij,ntj->nti", Cm, xu)
        return Cm.mean(axis=0), cv.mean(axis=0)
