"""The ensemble BIP filter (eBIP): spatiotemporal inference of the weights and the phase from a
partial observation of the interaction, then prediction of the unobserved degrees of freedom.

Equations: IntPrim's mathematical notes, "Ensemble Bayesian Interaction Primitives"; Campbell,
Stepputtis and Amor, "Probabilistic Multimodal Modeling for Human-Robot Interaction Tasks", RSS
2019 (the eBIP algorithm), after Evensen's ensemble Kalman filter (2003) with Burgers et al.'s
perturbed observations (1998):

- prediction: each member ``x_j <- G x_j + N(0, Q)`` with the constant-velocity phase model of
  eq. (2), ``phi <- phi + dt phi_dot`` and ``Q_{phi, phi_dot} = [[dt^4/4, dt^3/3], [dt^3/3, dt^2]]
  sigma_phi^2`` (the weights do not move);
- update: ``h(x_j) = Phi(phi_j)^T w_j`` of the observed degrees of freedom only, ``HA`` the
  members' deviations from their mean in measurement space, ``A`` in state space,
  ``S = HA HA^T / (E - 1) + R``, ``K = A HA^T S^-1 / (E - 1)``, and
  ``x_j <- x_j + K (y + eps_j - h(x_j))`` with ``eps_j ~ N(0, R)``.

The initial ensemble is ``E`` samples of the prior Gaussian (eq. 5), as in IntPrim's eBIP when the
ensemble is larger than the number of demonstrations. ``constraint`` adds the seed's 7.5 (see
:mod:`gazebot.apps.bip.constraint`): ``projection`` samples the ensemble from the prior projected
onto the grip-width constraint, ``filter`` projects every member onto it after every update.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum

import numpy as np

from gazebot.apps.bip.constraint import (
    LinearConstraint,
    constrain_members,
    grip_constraint,
    project_gaussian,
)
from gazebot.apps.bip.demos import RECEIVER_DOFS
from gazebot.apps.bip.prior import BipPrior


class ConstraintMode(str, Enum):
    """How the grip width enters (seed 7.5): not at all, in the prior, or in the filter."""

    NONE = "none"
    PROJECTION = "projection"
    FILTER = "filter"


@dataclass(frozen=True)
class FilterConfig:
    """Attributes:
    members: Ensemble size ``E``.
    phase_noise: ``sigma_phi`` of eq. (2) (phase units / s^2).
    observed: Indices of the observed degrees of freedom (default: the receiver's wrists, the
        human partner the robot sees; the robot's own wrists and the grip width are inferred).
    constraint_sd: ``filter``: the pseudo-observation's noise (m), imposed every update.
    perturb_constraint: ``filter``: perturb the pseudo-observation per member (Burgers et al.).
    projection_sd: ``projection``: the tolerance (m) the prior is conditioned with; 0 (the
        default) is the exact equality.
    """

    members: int = 100
    phase_noise: float = 1.0
    observed: tuple[int, ...] = RECEIVER_DOFS
    constraint_sd: float = 0.01
    projection_sd: float = 0.0
    perturb_constraint: bool = True


class EnsembleBIP:
    """One interaction's eBIP filter. ``width`` (m) is the carried object's grip width, used
    only by the ``projection`` and ``filter`` modes."""

    def __init__(
        self,
        prior: BipPrior,
        config: FilterConfig | None = None,
        mode: ConstraintMode | str = ConstraintMode.NONE,
        width: float | None = None,
        seed: int = 0,
    ) -> None:
        self.prior = prior
        self.config = cfg = config or FilterConfig()
        self.mode = ConstraintMode(mode)
        if cfg.members < 2:
            raise ValueError(f"an ensemble needs at least 2 members, got {cfg.members}")
        bad = [d for d in cfg.observed if not 0 <= d < prior.n_dof]
        if bad or not cfg.observed:
            raise ValueError(f"observed degrees of freedom must be in 0..{prior.n_dof - 1}, "
                             f"got {cfg.observed}")
        self.constraint: LinearConstraint | None = None
        if self.mode is not ConstraintMode.NONE:
            if width is None:
                raise ValueError(f"constraint {self.mode.value!r} needs the object's width")
            self.constraint = grip_constraint(prior, width)
        self._rng = np.random.default_rng(seed)
        mean, cov = prior.mean, prior.cov
        if self.mode is ConstraintMode.PROJECTION:
            assert self.constraint is not None
            mean, cov = project_gaussian(mean, cov, self.constraint, cfg.projection_sd)
        self.members = self._sample(mean, cov, cfg.members)
        obs = np.asarray(cfg.observed)
        self._obs = obs
        self._noise_var = prior.noise_var[obs]
        B = prior.n_basis
        # (the observed dofs' weight columns, (m, B))
        self._obs_cols = 2 + obs[:, None] * B + np.arange(B)

    def _sample(self, mean: np.ndarray, cov: np.ndarray, n: int) -> np.ndarray:
        """``n`` samples of ``N(mean, cov)`` for a positive semi-definite ``cov`` (a projected
        covariance is singular along the constraint)."""
        vals, vecs = np.linalg.eigh(cov)
        root = vecs * np.sqrt(np.clip(vals, 0.0, None))
        return mean + self._rng.standard_normal((n, mean.size)) @ root.T

    @property
    def phase(self) -> float:
        """Ensemble mean phase."""
        return float(self.members[:, 0].mean())

    @property
    def phase_velocity(self) -> float:
        return float(self.members[:, 1].mean())

    def propagate(self, dt: float) -> None:
        """Prediction step (eq. 2) over ``dt`` seconds."""
        q = self.config.phase_noise**2 * np.array(
            [[dt**4 / 4.0, dt**3 / 3.0], [dt**3 / 3.0, dt**2]]
        )
        vals, vecs = np.linalg.eigh(q)
        root = vecs * np.sqrt(np.clip(vals, 0.0, None))
        x = self.members
        x[:, 0] += dt * x[:, 1]
        x[:, :2] += self._rng.standard_normal((x.shape[0], 2)) @ root.T

    def measure(self, members: np.ndarray | None = None) -> np.ndarray:
        """``h(x_j)``: ``(E, m)`` the observed degrees of freedom of each member at its phase."""
        x = self.members if members is None else members
        phi = self.prior.basis.values(x[:, 0])  # (E, B)
        w = x[:, self._obs_cols]  # (E, m, B)
        return np.einsum("eb,emb->em", phi, w)

    def update(self, y: Sequence[float] | np.ndarray) -> None:
        """Measurement update with one sample ``y`` of the observed degrees of freedom."""
        y = np.asarray(y, float)
        if y.shape != self._obs.shape:
            raise ValueError(f"expected {self._obs.size} observed values, got shape {y.shape}")
        x = self.members
        e = x.shape[0]
        hx = self.measure()
        ha = hx - hx.mean(axis=0)
        a = x - x.mean(axis=0)
        s = ha.T @ ha / (e - 1) + np.diag(self._noise_var)
        cross = a.T @ ha / (e - 1)  # (n, m)
        gain = np.linalg.solve(s, cross.T).T
        perturbed = y + self._rng.standard_normal(hx.shape) * np.sqrt(self._noise_var)
        x += (perturbed - hx) @ gain.T
        if self.mode is ConstraintMode.FILTER:
            assert self.constraint is not None
            self.members = constrain_members(x, self.constraint, self.config.constraint_sd,
                                             self._rng if self.config.perturb_constraint else None)

    def step(self, y: Sequence[float] | np.ndarray, dt: float) -> None:
        """One tick: :meth:`propagate` by ``dt``, then :meth:`update` with ``y``."""
        self.propagate(dt)
        self.update(y)

    def predict(self, horizon: np.ndarray, dofs: Sequence[int] | None = None) -> np.ndarray:
        """Ensemble-mean prediction ``(T, len(dofs))`` at ``horizon`` s ahead (``(T,)``, >= 0)
        of ``dofs`` (default all): each member at its own phase ``phi_j + tau phi_dot_j``
        (held at 1 once the motion is over)."""
        x = self.members
        idx = np.arange(self.prior.n_dof) if dofs is None else np.asarray(dofs, dtype=int)
        B = self.prior.n_basis
        phase = np.clip(x[:, 0][:, None] + np.asarray(horizon)[None, :] * x[:, 1][:, None],
                        0.0, 1.0)  # (E, T)
        phi = self.prior.basis.values(phase)  # (E, T, B)
        w = x[:, 2 + idx[:, None] * B + np.arange(B)]  # (E, k, B)
        return np.einsum("etb,ekb->tk", phi, w) / x.shape[0]
