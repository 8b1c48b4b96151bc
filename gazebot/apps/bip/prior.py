"""The BIP prior: each demonstration's basis weights, phase velocity and fit residuals, and their
joint Gaussian over the state ``s = [phi, phi_dot, w]``.

Equations (IntPrim's mathematical notes, "Bayesian Interaction Primitives"; Campbell and Amor,
"Bayesian Interaction Primitives: A SLAM approach to human-robot interaction", CoRL 2017):
``w_0`` is the mean of the demonstrations' weights, ``phi_0 = 0``, ``phi_dot_0`` the mean of
``1 / T_i``, and eq. (5): ``Sigma_0 = blockdiag(var(phi), var(phi_dot), cov(W))``. The measurement
noise ``R`` is the variance of each degree of freedom's basis-fit residual over the
demonstrations ("automatic computation of the observation noise", IntPrim), floored at the
sensor's noise.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gazebot.apps.bip.basis import GaussianBasis, fit_weights, reconstruct
from gazebot.apps.bip.demos import DOF_NAMES, GIVER_DOFS, Demonstration, wrist_distance
from gazebot.io.recordings import RecordingError

PHASE_GRID = np.linspace(0.0, 1.0, 101)


@dataclass(frozen=True)
class TrainConfig:
    """How demonstrations become a prior.

    Attributes:
        basis: The radial basis on the phase.
        ridge: Ridge term of the weight fit.
        phase_sd: Standard deviation of the initial phase (every demonstration starts at 0).
        weight_jitter_m: Added to the weights' standard deviations (m): the sample covariance of
            a few demonstrations is singular, and conditioning needs it positive definite.
        noise_floor_m: Least measurement noise standard deviation (m). It stands for the model
            error of a new interaction (the prior cannot reproduce it exactly), not only the
            tracker's (docs/seed/bip.md).
    """

    basis: GaussianBasis = GaussianBasis()
    ridge: float = 1e-6
    phase_sd: float = 0.01
    weight_jitter_m: float = 1e-3
    noise_floor_m: float = 0.01


@dataclass(frozen=True)
class BipPrior:
    """The trained model: prior mean and covariance over ``[phi, phi_dot, w]`` (weights ``w`` in
    degree-of-freedom-major order, ``w[d * B + b]``), the measurement noise per degree of
    freedom, and the training demonstrations on a common phase grid (for figures)."""

    basis: GaussianBasis
    mean: np.ndarray  # (2 + D*B,)
    cov: np.ndarray  # (2 + D*B, 2 + D*B)
    noise_var: np.ndarray  # (D,) m^2
    widths: np.ndarray  # (N,) grip widths of the training demonstrations, m
    durations: np.ndarray  # (N,) s
    curves: np.ndarray  # (N, len(PHASE_GRID), D) demonstrations resampled on PHASE_GRID
    dof_names: tuple[str, ...] = DOF_NAMES

    @property
    def n_dof(self) -> int:
        return len(self.dof_names)

    @property
    def n_basis(self) -> int:
        return self.basis.n

    @property
    def weight_mean(self) -> np.ndarray:
        """``(D, B)`` mean weights."""
        return self.mean[2:].reshape(self.n_dof, self.n_basis)

    @property
    def width_mean(self) -> float:
        """Mean grip width of the training demonstrations (m)."""
        return float(np.mean(self.widths))

    def mean_trajectory(self, phase: np.ndarray) -> np.ndarray:
        """``(T, D)`` the prior mean's trajectory at ``phase``."""
        return reconstruct(self.basis, phase, self.weight_mean)

    def mean_giver_distance(self) -> np.ndarray:
        """Mean over the training demonstrations of the giver's wrist distance on PHASE_GRID."""
        return wrist_distance(self.curves[:, :, list(GIVER_DOFS)]).mean(axis=0)

    # ------------------------------------------------------------------ files
    def save(self, folder: str | Path) -> Path:
        """Write ``folder/bip_prior.npz`` (arrays) and ``folder/bip_prior.json`` (a summary)."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / "bip_prior.npz"
        np.savez(
            path,
            basis=np.array([self.basis.n, self.basis.width]),
            mean=self.mean,
            cov=self.cov,
            noise_var=self.noise_var,
            widths=self.widths,
            durations=self.durations,
            curves=self.curves,
            dof_names=np.array(self.dof_names),
        )
        summary = {
            "demonstrations": int(self.widths.size),
            "basis_functions": self.basis.n,
            "basis_width": self.basis.width,
            "state_dim": int(self.mean.size),
            "width_mean_m": self.width_mean,
            "widths_m": [round(float(w), 4) for w in self.widths],
            "phase_velocity_mean_per_s": float(self.mean[1]),
            "noise_sd_m": dict(zip(self.dof_names, np.sqrt(self.noise_var).round(5).tolist(),
                                   strict=True)),
        }
        (folder / "bip_prior.json").write_text(json.dumps(summary, indent=2) + "\n",
                                               encoding="utf-8")
        return path

    @classmethod
    def load(cls, folder: str | Path) -> BipPrior:
        """Read what :meth:`save` wrote (``folder`` or the ``.npz`` itself)."""
        path = Path(folder)
        if path.suffix != ".npz":
            path = path / "bip_prior.npz"
        if not path.is_file():
            raise RecordingError(path, "no such file; expected the folder a `gazebot bip train "
                                 "--out` wrote")
        try:
            with np.load(path, allow_pickle=False) as z:
                n, width = z["basis"]
                prior = cls(
                    basis=GaussianBasis(int(n), float(width)),
                    mean=z["mean"],
                    cov=z["cov"],
                    noise_var=z["noise_var"],
                    widths=z["widths"],
                    durations=z["durations"],
                    curves=z["curves"],
                    dof_names=tuple(str(s) for s in z["dof_names"]),
                )
        except (OSError, ValueError, KeyError) as exc:
            raise RecordingError(path, f"not a BIP prior written by gazebot ({exc})") from None
        if prior.dof_names != DOF_NAMES:
            raise RecordingError(path, f"degrees of freedom {prior.dof_names}; expected "
                                 f"{DOF_NAMES}")
        if prior.mean.shape != (2 + prior.n_dof * prior.n_basis,):
            raise RecordingError(path, "field mean: wrong size for the basis")
        return prior


def train(demos: Sequence[Demonstration], config: TrainConfig | None = None) -> BipPrior:
    """Fit every demonstration's weights and build the prior (eq. 5).

    Raises:
        ValueError: fewer than two demonstrations (no covariance).
    """
    cfg = config or TrainConfig()
    if len(demos) < 2:
        raise ValueError(f"a BIP prior needs at least 2 demonstrations, got {len(demos)}")
    basis = cfg.basis
    weights, residual_sq, curves = [], [], []
    for d in demos:
        w = fit_weights(basis, d.phase, d.y, cfg.ridge)
        weights.append(w.ravel())
        residual_sq.append(np.mean((reconstruct(basis, d.phase, w) - d.y) ** 2, axis=0))
        curves.append(np.stack([np.interp(PHASE_GRID, d.phase, col) for col in d.y.T], axis=1))
    W = np.array(weights)
    rate = np.array([1.0 / d.duration for d in demos])
    n = W.shape[1]
    mean = np.concatenate([[0.0, rate.mean()], W.mean(axis=0)])
    cov = np.zeros((n + 2, n + 2))
    cov[0, 0] = cfg.phase_sd**2
    cov[1, 1] = rate.var(ddof=1)
    cov[2:, 2:] = np.cov(W, rowvar=False) + cfg.weight_jitter_m**2 * np.eye(n)
    noise_var = np.maximum(np.mean(residual_sq, axis=0), cfg.noise_floor_m**2)
    return BipPrior(
        basis=basis,
        mean=mean,
        cov=cov,
        noise_var=noise_var,
        widths=np.array([d.width for d in demos]),
        durations=np.array([d.duration for d in demos]),
        curves=np.array(curves),
    )
