"""The grip-width constraint of the seed's 7.5 as a linear equality on the BIP state, and the two
ways of imposing it.

The seed (7.5): "The first solution involves updating the trained distributions of BIPs to satisfy
the grip width constraint, and the second solution involves imposing this constraint during the
inference process. The first solution is similar to the method proposed by Frank et al. [52] for
adapting ProMPs [...] to minimize the Kullback-Leibler divergence between the adapted distribution
and the distribution of the original primitive while adhering to the constraints. The second
solution is to impose the constraint in the spatiotemporal filters that are used in BIPs for
inference, for example, by utilizing constrained Ensemble Kalman methods [2]."

The constraint set, linear in the weights ``w`` (so that both solutions are closed-form):

- the grip-width degree of freedom equals the object's width ``g`` at every basis centre:
  ``Phi(c_k)^T w_width = g``;
- the giver's wrist separation equals ``g`` times the prior mean's grip axis at every basis
  centre: ``Phi(c_k)^T (w_left,a - w_right,a) = g u_a(c_k)`` for ``a`` in x, y, z, where
  ``u(phi)`` is the unit direction of the prior mean's ``left - right``. Then
  ``|left - right| = g`` along the whole reach, the hands keep the prior's grip axis, and the
  rest of the motion (where the hands are) is free.

``axis_only=True`` constrains only the separation's component along ``u`` (the distance
linearised about the prior's axis, 9 rows instead of 27): it leaves the grip axis free, and with
a prior from 8 demonstrations conditioning on a narrow box turned that axis by up to 30 degrees
(spurious width-yaw correlations), 3.8 cm off the width (docs/seed/bip.md).

:func:`project_gaussian` is the first solution: the Gaussian ``q`` that minimises ``KL(q || p)``
among distributions whose samples satisfy ``A s = b`` is ``p`` conditioned on ``A s = b``
(closed form, as in ProMP conditioning/adaptation: Paraschos et al., NIPS 2013, eq. 5; Frank et
al., "Constrained Probabilistic Movement Primitives for Robot Trajectory Adaptation", IEEE T-RO
2022, for equality constraints that hold almost surely). :func:`project_members` is the second:
after every ensemble update each member is projected onto the constraint set in the metric of the
ensemble covariance ``P`` (the "estimate projection" of Simon and Chia, IEEE T-AES 2002, with
``W = P^-1``, applied member by member, as reviewed for ensemble Kalman filters by Amor et al.,
"Constrained state estimation - a review", 2018): ``x <- x + P A^T (A P A^T)^-1 (b - A x)``, the
update of a perfect pseudo-observation ``A x = b``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gazebot.apps.bip.demos import GIVER_DOFS, WIDTH_DOF
from gazebot.apps.bip.prior import BipPrior

# Ridge on A P A^T (m^2): keeps a nearly collapsed ensemble's projection finite.
PROJECTION_RIDGE = 1e-12


@dataclass(frozen=True)
class LinearConstraint:
    """``A s = b`` on the BIP state ``s = [phi, phi_dot, w]``."""

    A: np.ndarray  # (m, n)
    b: np.ndarray  # (m,)

    def residual(self, states: np.ndarray) -> np.ndarray:
        """``A s - b`` for ``(n,)`` or ``(E, n)`` states."""
        return np.asarray(states) @ self.A.T - self.b


def grip_constraint(prior: BipPrior, width: float, axis_only: bool = False) -> LinearConstraint:
    """The grip-width constraint for an object ``width`` m wide (see the module docstring):
    the separation ``left - right`` equals ``width u(c_k)``, or with ``axis_only`` only its
    component along ``u(c_k)`` equals ``width``."""
    if not (np.isfinite(width) and width > 0.0):
        raise ValueError(f"grip width must be a positive number of m, got {width}")
    B, D = prior.n_basis, prior.n_dof
    n = 2 + D * B

    def col(dof: int) -> slice:
        return slice(2 + dof * B, 2 + (dof + 1) * B)

    rows, targets = [], []
    # (more phases than basis functions would make nearly dependent rows)
    phases = prior.basis.centers
    values = prior.basis.values(phases)
    for phi_row in values:
        row = np.zeros(n)
        row[col(WIDTH_DOF)] = phi_row
        rows.append(row)
        targets.append(width)
    mean = prior.mean_trajectory(phases)
    left, right = GIVER_DOFS[:3], GIVER_DOFS[3:]
    sep = mean[:, list(left)] - mean[:, list(right)]
    axis = sep / np.linalg.norm(sep, axis=1, keepdims=True)
    for phi_row, u in zip(values, axis, strict=True):
        if axis_only:
            row = np.zeros(n)
            for a in range(3):
                row[col(left[a])] = u[a] * phi_row
                row[col(right[a])] = -u[a] * phi_row
            rows.append(row)
            targets.append(width)
            continue
        for a in range(3):
            row = np.zeros(n)
            row[col(left[a])] = phi_row
            row[col(right[a])] = -phi_row
            rows.append(row)
            targets.append(width * u[a])
    return LinearConstraint(A=np.array(rows), b=np.array(targets, float))


def project_gaussian(
    mean: np.ndarray, cov: np.ndarray, constraint: LinearConstraint, noise_sd: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """``N(mean, cov)`` conditioned on ``A s = b + eps``, ``eps ~ N(0, noise_sd^2 I)``.

    ``mean' = mean + K (b - A mean)``, ``cov' = cov - K A cov``,
    ``K = cov A^T (A cov A^T + noise_sd^2 I)^-1``: ProMP conditioning on a desired point with
    accuracy ``noise_sd`` (Paraschos et al. 2013, eq. 5). With ``noise_sd = 0`` it is the
    KL-minimal Gaussian on the constraint set itself.
    """
    A = constraint.A
    cat = cov @ A.T
    gain = np.linalg.solve(A @ cat + noise_sd**2 * np.eye(A.shape[0]), cat.T).T
    new_mean = mean + gain @ (constraint.b - A @ mean)
    new_cov = cov - gain @ cat.T
    return new_mean, 0.5 * (new_cov + new_cov.T)


def constrain_members(
    members: np.ndarray,
    constraint: LinearConstraint,
    noise_sd: float,
    rng: np.random.Generator | None = None,
) -> np.ndarray:
    """The ``(E, n)`` ensemble updated with the pseudo-observation ``A x = b + eps``,
    ``eps ~ N(0, noise_sd^2 I)``: ``x_j <- x_j + P A^T (A P A^T + noise_sd^2 I)^-1 (b + eps_j -
    A x_j)`` with ``P`` the ensemble covariance. ``rng`` perturbs ``b`` per member (Burgers et al.);
    ``None`` leaves it unperturbed. ``noise_sd -> 0`` is the projection of each member onto the
    constraint set in the ensemble covariance's metric."""
    A = constraint.A
    anomalies = members - members.mean(axis=0)
    ca = anomalies @ A.T  # (E, m)
    e1 = max(members.shape[0] - 1, 1)
    # P A^T = anomalies^T ca / (E - 1); A P A^T = ca^T ca / (E - 1)
    apa = ca.T @ ca / e1 + (noise_sd**2 + PROJECTION_RIDGE) * np.eye(A.shape[0])
    pat = anomalies.T @ ca / e1
    target = np.broadcast_to(constraint.b, ca.shape)
    if rng is not None:
        target = target + noise_sd * rng.standard_normal(ca.shape)
    correction = np.linalg.solve(apa, (target - members @ A.T).T)  # (m, E)
    return members + (pat @ correction).T
