"""The STL reach MILP of one receding-horizon step (seed eqs. 4.1-4.4), assembled as sparse
matrices and solved with HiGHS through ``scipy.optimize.milp``.

Variables, ``H`` steps of a ``D``-dimensional integrator (D = 3 for the end effector's position,
1 for the gripper's openness; eq. 4.2 makes both ``x_dot = u``): velocities ``u`` (H x D), their
absolute values ``a`` (H x D), the absolute gaps ``d`` (H x D) and one binary ``b_j`` per step
("near at x_j"):

    min  sum a
    s.t. -u_max <= u <= u_max,  a >= |u|
         x_j = x_0 + dt sum_{i<j} u_i                         (eq. 4.2, j = 1..H)
         d_j >= |x_j - target_j|,  sum_axes d_j <= eps + M (1 - b_j)   (l1 near, big-M)
         W b >= r           (each required window has a near step)

:func:`solve_reach_milp_cvxpy` states the same problem in cvxpy (a cross-check in the tests and
the benchmark's peer): the direct assembly skips cvxpy's per-solve canonicalization.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.optimize import Bounds, LinearConstraint, milp


@dataclass(frozen=True)
class ReachMILP:
    """One step's problem data (base frame, m, s)."""

    x0: np.ndarray  # (D,) the state now (end effector position, or gripper openness)
    target: np.ndarray  # (H, D) where to be near at x_1..x_H
    windows: np.ndarray  # (R, H) 0/1: which steps each required window covers
    required: np.ndarray  # (R,) 1 where the window must hold a near step
    dt: float
    u_max: float
    eps: float  # the l1 tolerance the plan must meet

    @property
    def horizon(self) -> int:
        return len(self.target)

    @property
    def dim(self) -> int:
        return len(np.asarray(self.x0).reshape(-1))

    def big_m(self) -> np.ndarray:
        """Per-step big-M: the largest l1 gap ``x_j`` can have from ``target_j`` at the speed cap
        (a tight M keeps the LP relaxation, and so the branch and bound, small)."""
        j = np.arange(1, self.horizon + 1)
        start = np.abs(np.asarray(self.target, float) - np.asarray(self.x0, float)).sum(axis=1)
        return start + self.dim * self.u_max * self.dt * j + self.eps


def solve_reach_milp(p: ReachMILP, mip_gap: float = 1e-4) -> tuple[np.ndarray | None, str]:
    """``(u (H, D), "optimal")`` or ``(None, reason)`` when no input meets the windows."""
    H, dim = p.horizon, p.dim
    n3 = dim * H
    # Column blocks: u [0, n3), a [n3, 2 n3), d [2 n3, 3 n3), b [3 n3, 3 n3 + H)
    I3 = sparse.identity(n3, format="csr")
    Z3 = sparse.csr_matrix((n3, n3))
    ZB = sparse.csr_matrix((n3, H))
    # x_flat = x0_tiled + S u_flat, S = kron(dt * tril(ones), I_D) (row-major (j, axis))
    S = sparse.kron(sparse.csr_matrix(np.tril(np.ones((H, H))) * p.dt), sparse.identity(dim))
    x_free = np.tile(np.asarray(p.x0, float), H) - np.asarray(p.target, float).reshape(-1)
    M = p.big_m()
    rows = [
        # a - u >= 0 ; a + u >= 0
        (sparse.hstack([-I3, I3, Z3, ZB]), np.zeros(n3), np.full(n3, np.inf)),
        (sparse.hstack([I3, I3, Z3, ZB]), np.zeros(n3), np.full(n3, np.inf)),
        # d - (x - target) >= 0  ->  d - S u >= x0 - target ; d + S u >= target - x0
        (sparse.hstack([-S, Z3, I3, ZB]), x_free, np.full(n3, np.inf)),
        (sparse.hstack([S, Z3, I3, ZB]), -x_free, np.full(n3, np.inf)),
        # sum_axes d_j + M b_j <= eps + M
        (
            sparse.hstack(
                [
                    sparse.csr_matrix((H, n3)),
                    sparse.csr_matrix((H, n3)),
                    sparse.kron(sparse.identity(H), np.ones((1, dim))),
                    sparse.diags(M),
                ]
            ),
            np.full(H, -np.inf),
            p.eps + M,
        ),
    ]
    active = np.asarray(p.required, float) > 0
    if active.any():
        Wd = np.asarray(p.windows, float)[active]
        W = sparse.csr_matrix(Wd)
        rows.append(
            (
                sparse.hstack([sparse.csr_matrix((W.shape[0], 3 * n3)), W]),
                np.ones(W.shape[0]),
                np.full(W.shape[0], np.inf),
            )
        )
        # A valid cut: meeting a window takes at least the l1 way to its nearest target step,
        # dt sum |u| >= min_{j in window} |target_j - x_0|_1 - eps. It makes the relaxation's
        # bound exact for a still target, so HiGHS need not branch over which step is near.
        gap0 = np.abs(np.asarray(p.target, float) - np.asarray(p.x0, float)).sum(axis=1)
        need = max(float(np.min(np.where(w > 0, gap0, np.inf))) for w in Wd) - p.eps
        if np.isfinite(need) and need > 0:
            rows.append(
                (
                    sparse.hstack(
                        [
                            sparse.csr_matrix((1, n3)),
                            sparse.csr_matrix(np.full((1, n3), p.dt)),
                            sparse.csr_matrix((1, n3 + H)),
                        ]
                    ),
                    np.array([need]),
                    np.array([np.inf]),
                )
            )
    A = sparse.vstack([r[0] for r in rows], format="csr")
    lb = np.concatenate([r[1] for r in rows])
    ub = np.concatenate([r[2] for r in rows])
    c = np.concatenate([np.zeros(n3), np.ones(n3), np.zeros(n3 + H)])
    lo = np.concatenate([np.full(n3, -p.u_max), np.zeros(2 * n3 + H)])
    hi = np.concatenate([np.full(n3, p.u_max), np.full(2 * n3, np.inf), np.ones(H)])
    integrality = np.concatenate([np.zeros(3 * n3), np.ones(H)])
    res = milp(
        c,
        constraints=LinearConstraint(A, lb, ub),
        bounds=Bounds(lo, hi),
        integrality=integrality,
        options={"mip_rel_gap": mip_gap},
    )
    if res.status != 0 or res.x is None:
        return None, "infeasible" if res.status == 2 else f"status {res.status}: {res.message}"
    return np.asarray(res.x[:n3], float).reshape(H, dim), "optimal"


def solve_reach_milp_cvxpy(p: ReachMILP, solver: str = "SCIPY") -> tuple[np.ndarray | None, str]:
    """The same MILP built and solved through cvxpy (default solver: SciPy's HiGHS)."""
    import cvxpy as cp

    H, dim = p.horizon, p.dim
    U = cp.Variable((H, dim))
    b = cp.Variable(H, boolean=True)
    Au = cp.Variable((H, dim))
    D = cp.Variable((H, dim))
    X = (
        np.ones((H, 1)) @ np.asarray(p.x0, float).reshape(1, dim)
        + (np.tril(np.ones((H, H))) * p.dt) @ U
    )
    cons = [
        U <= p.u_max,
        U >= -p.u_max,
        Au >= U,
        Au >= -U,
        D >= X - p.target,
        D >= p.target - X,
        cp.sum(D, axis=1) <= p.eps + cp.multiply(p.big_m(), 1 - b),
    ]
    active = np.asarray(p.required, float) > 0
    if active.any():
        Wd = np.asarray(p.windows, float)[active]
        cons.append(Wd @ b >= 1)
        gap0 = np.abs(np.asarray(p.target, float) - np.asarray(p.x0, float)).sum(axis=1)
        need = max(float(np.min(np.where(w > 0, gap0, np.inf))) for w in Wd) - p.eps
        if np.isfinite(need) and need > 0:
            cons.append(p.dt * cp.sum(Au) >= need)  # the same cut as solve_reach_milp
    prob = cp.Problem(cp.Minimize(cp.sum(Au)), cons)
    try:
        prob.solve(solver=solver)
    except cp.SolverError as exc:
        return None, f"solver_error: {exc}"
    if prob.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) or U.value is None:
        return None, str(prob.status)
    return np.asarray(U.value, float), "optimal"
