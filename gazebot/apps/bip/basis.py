"""Gaussian radial basis functions on the phase, and a demonstration's weights.

Each degree of freedom ``d`` is approximated as ``y_d(phi) = Phi(phi)^T w_d`` (IntPrim's
mathematical notes, "Basis Function Decomposition"; Campbell and Amor, CoRL 2017, sec. 3), with
``Phi(phi)`` the ``B`` Gaussian bumps ``exp(-(phi - c_b)^2 / (2 h^2))`` centred evenly on [0, 1],
normalised to sum 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class GaussianBasis:
    """``n`` Gaussian bumps of width ``width`` (in phase units) centred evenly on [0, 1]."""

    n: int = 9
    width: float = 0.08

    def __post_init__(self) -> None:
        if self.n < 2:
            raise ValueError(f"a basis needs at least 2 functions, got {self.n}")
        if not (np.isfinite(self.width) and self.width > 0.0):
            raise ValueError(f"basis width must be a positive number, got {self.width}")

    @classmethod
    def spaced(cls, n: int) -> GaussianBasis:
        """``n`` functions whose width is 0.64 of their spacing (the default's ratio: 9 at 0.08)."""
        if n < 2:
            raise ValueError(f"a basis needs at least 2 functions, got {n}")
        return cls(n, 0.64 / (n - 1))

    @property
    def centers(self) -> np.ndarray:
        return np.linspace(0.0, 1.0, self.n)

    def _bumps(self, phase: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """The unnormalised bumps ``g`` and their derivatives ``dg/dphi``, ``(..., n)`` each,
        up to a common positive factor per phase."""
        d = (np.asarray(phase, float)[..., None] - self.centers) / self.width
        # Scaled by the largest bump (the ratios do not change): far outside [0, 1] every
        # bump would underflow to 0 and the normalisation to 0 / 0.
        e = -0.5 * d**2
        g = np.exp(e - e.max(axis=-1, keepdims=True))
        return g, -d / self.width * g

    def values(self, phase: np.ndarray | float) -> np.ndarray:
        """``Phi`` at each phase: shape ``(..., n)`` for phases of shape ``(...)``; normalised to
        sum 1 (as ProMPs' basis, Paraschos et al. 2013), so a constant is represented exactly
        up to the ends of [0, 1]."""
        g, _ = self._bumps(phase)
        return g / g.sum(axis=-1, keepdims=True)

    def derivative(self, phase: np.ndarray | float) -> np.ndarray:
        """``dPhi/dphi`` at each phase, shape ``(..., n)`` (for the EKF Jacobian, eq. 3)."""
        g, dg = self._bumps(phase)
        total = g.sum(axis=-1, keepdims=True)
        return (dg * total - g * dg.sum(axis=-1, keepdims=True)) / total**2


def fit_weights(
    basis: GaussianBasis, phase: np.ndarray, y: np.ndarray, ridge: float = 1e-6
) -> np.ndarray:
    """Ridge least squares ``argmin_W |Phi W - Y|^2 + ridge |W|^2`` of one demonstration.

    Args:
        phase: ``(T,)`` phases of the samples in [0, 1].
        y: ``(T, D)`` samples.
    Returns:
        ``(D, n)`` weights, one row per degree of freedom.
    """
    phi = basis.values(phase)
    lhs = phi.T @ phi + ridge * np.eye(basis.n)
    return np.linalg.solve(lhs, phi.T @ np.asarray(y, float)).T


def reconstruct(basis: GaussianBasis, phase: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """``(T, D)`` trajectory of ``(D, n)`` weights at ``(T,)`` phases."""
    return basis.values(phase) @ np.asarray(weights, float).T
