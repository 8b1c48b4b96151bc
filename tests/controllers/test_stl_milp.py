"""The directly assembled STL reach MILP agrees with the same problem stated in cvxpy."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.controllers.stl_milp import ReachMILP, solve_reach_milp, solve_reach_milp_cvxpy


def _problem(rng, H=6, deadline=5, eps=0.009):
    W = np.zeros((H + 1, H))
    W[0, :deadline] = 1
    r = np.zeros(H + 1)
    r[0] = 1
    target = rng.uniform(-0.6, 0.6, 3) + np.cumsum(rng.normal(0, 0.02, (H, 3)), axis=0)
    return ReachMILP(np.zeros(3), target, W, r, dt=0.2, u_max=1.0, eps=eps)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_direct_milp_matches_cvxpy_on_the_optimum(seed):
    p = _problem(np.random.default_rng(seed))
    U, status = solve_reach_milp(p)
    V, status_cvx = solve_reach_milp_cvxpy(p)
    assert status == status_cvx == "optimal"
    assert np.abs(U).sum() == pytest.approx(np.abs(V).sum(), rel=1e-3, abs=1e-6)
    # the plan meets its window: some step within the deadline is within eps (l1)
    x = p.x0 + np.cumsum(U * p.dt, axis=0)
    assert (np.abs(x - p.target).sum(axis=1)[:5] <= p.eps + 1e-6).any()
    assert np.abs(U).max() <= p.u_max + 1e-9


def test_unreachable_window_is_infeasible_for_both():
    p = _problem(np.random.default_rng(0), deadline=1)
    p = ReachMILP(p.x0, np.tile([1.5, 0, 0], (6, 1)), p.windows, p.required, 0.2, 1.0, 0.009)
    assert solve_reach_milp(p)[0] is None
    assert solve_reach_milp_cvxpy(p)[0] is None
