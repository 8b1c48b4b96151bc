"""The STL reach MILP against formulations that share none of its encoding.

``solve_reach_milp`` and its cvxpy twin share ``big_m()`` and the path-length cut, so a wrong
big-M or cut would pass a comparison of the two. The checks here do not use either:

- the exact optimum by disjunction: for every choice of one near step per required window, a
  linear program over the *positions* ``x_1..x_H`` (no binaries, no big-M, no cut), minimized
  over the choices (``_reference_optimum``);
- the plan's own robustness: each required window, evaluated directly on the integrated
  positions, holds a step within ``eps`` (l1) of its target, and the speed cap holds;
- exhaustive search on a tiny instance: no input sequence from a grid over the input set that
  meets the windows (evaluated directly) costs less than the MILP's optimum.

The last tests break the encoding on purpose and show the checks catch each break (while the
cvxpy twin, sharing ``big_m``, agrees with a broken big-M).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pytest
from scipy import sparse
from scipy.optimize import linprog

from gazebot.apps.controllers.stl_milp import ReachMILP, solve_reach_milp, solve_reach_milp_cvxpy

Solver = Callable[[ReachMILP], tuple[np.ndarray | None, str]]
TOL = 1e-6


def _problem(rng, H=6, deadline=5, eps=0.009):
    W = np.zeros((H + 1, H))
    W[0, :deadline] = 1
    r = np.zeros(H + 1)
    r[0] = 1
    target = rng.uniform(-0.6, 0.6, 3) + np.cumsum(rng.normal(0, 0.02, (H, 3)), axis=0)
    return ReachMILP(np.zeros(3), target, W, r, dt=0.2, u_max=1.0, eps=eps)


def _two_windows(rng, H=6):
    """A window on the first four steps and a second one on the last three, toward a moving
    target: the plan must be near twice."""
    W = np.zeros((2, H))
    W[0, :4] = 1
    W[1, 3:] = 1
    target = rng.uniform(-0.3, 0.3, 3) + np.outer(np.arange(1, H + 1), rng.uniform(-0.1, 0.1, 3))
    return ReachMILP(np.zeros(3), target, W, np.ones(2), dt=0.2, u_max=1.0, eps=0.009)


def _required_windows(p: ReachMILP) -> list[np.ndarray]:
    return [np.flatnonzero(w) for w, r in zip(p.windows, p.required, strict=True) if r > 0]


def _positions(p: ReachMILP, U: np.ndarray) -> np.ndarray:
    """x_1..x_H of x_{j+1} = x_j + u_j dt (eq. 4.2)."""
    return np.asarray(p.x0, float) + np.cumsum(np.asarray(U, float) * p.dt, axis=0)


def _robustness(p: ReachMILP, U: np.ndarray) -> float:
    """min over required windows of max over its steps of ``eps - ||x_j - target_j||_1``."""
    gap = np.abs(_positions(p, U) - p.target).sum(axis=1)
    return min((float(np.max(p.eps - gap[w])) for w in _required_windows(p)), default=np.inf)


def _reference_optimum(p: ReachMILP) -> float | None:
    """min sum |u| by enumerating the near steps, one LP over positions per choice."""
    H, d = p.horizon, len(np.ravel(p.x0))
    n = d * H  # x (positions), s (|x_j - x_{j-1}| per axis), t (|x_j - target_j| per axis)
    # x_j - x_{j-1} as a matrix D on x (x_0 fixed: its term moves to the bounds)
    D = sparse.kron(sparse.eye(H) - sparse.eye(H, k=-1), sparse.eye(d))
    x0_term = np.r_[np.asarray(p.x0, float), np.zeros(n - d)]
    Id, Z = sparse.eye(n), sparse.csr_matrix((n, n))
    base_ub = [
        (sparse.hstack([D, -Id, Z]), x0_term),  # (x_j - x_{j-1}) <= s
        (sparse.hstack([-D, -Id, Z]), -x0_term),  # -(x_j - x_{j-1}) <= s
        (sparse.hstack([Id, Z, -Id]), p.target.reshape(-1)),  # x - target <= t
        (sparse.hstack([-Id, Z, -Id]), -p.target.reshape(-1)),  # target - x <= t
    ]
    bounds = [(None, None)] * n + [(0, p.u_max * p.dt)] * n + [(0, None)] * n
    c = np.r_[np.zeros(n), np.full(n, 1 / p.dt), np.zeros(n)]
    best = None
    for near in itertools.product(*_required_windows(p)):
        rows = [r[0] for r in base_ub]
        rhs = [r[1] for r in base_ub]
        for j in sorted(set(near)):  # sum over axes of t_j <= eps
            sel = np.zeros((1, 3 * n))
            sel[0, 2 * n + d * j : 2 * n + d * j + d] = 1
            rows.append(sparse.csr_matrix(sel))
            rhs.append(np.array([p.eps]))
        res = linprog(
            c, A_ub=sparse.vstack(rows), b_ub=np.concatenate(rhs), bounds=bounds, method="highs"
        )
        if res.status == 0 and (best is None or res.fun < best):
            best = float(res.fun)
    return best


def independent_discrepancies(p: ReachMILP, solve: Solver = solve_reach_milp) -> list[str]:
    """What the solver's answer gets wrong by the checks in the module doc (empty: none)."""
    U, status = solve(p)
    ref = _reference_optimum(p)
    if U is None:
        return [] if ref is None else [f"{status} but the optimum is {ref:.6f}"]
    out = []
    if ref is None:
        out.append("a plan where no input meets the windows")
    elif not np.isclose(np.abs(U).sum(), ref, rtol=2e-4, atol=TOL):
        out.append(f"cost {np.abs(U).sum():.6f}, optimum {ref:.6f}")
    if _robustness(p, U) < -TOL:
        out.append(f"plan misses a window (robustness {_robustness(p, U):.4f})")
    if np.abs(U).max() > p.u_max + TOL:
        out.append("plan exceeds the speed cap")
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_milp_optimum_equals_the_disjunctive_lp_and_its_plan_meets_the_window(seed):
    assert independent_discrepancies(_problem(np.random.default_rng(seed))) == []


@pytest.mark.parametrize("seed", [3, 4])
def test_two_windows_on_a_moving_target_agree_with_the_disjunctive_lp(seed):
    p = _two_windows(np.random.default_rng(seed))
    assert independent_discrepancies(p) == []
    U, _ = solve_reach_milp(p)
    gap = np.abs(_positions(p, U) - p.target).sum(axis=1)
    assert (gap[:4] <= p.eps + TOL).any() and (gap[3:] <= p.eps + TOL).any()


def test_a_one_dimensional_state_the_gripper_agrees_with_the_disjunctive_lp():
    """The gripper's openness (``STLGripper``): 1 -> within 0.08 of 0 at 4/s in 0.2 s steps."""
    H = 6
    W = np.zeros((1, H))
    W[0, :3] = 1
    p = ReachMILP(np.array([1.0]), np.zeros((H, 1)), W, np.ones(1), 0.2, 4.0, 0.08)
    assert independent_discrepancies(p) == []
    U, _ = solve_reach_milp(p)
    assert U.shape == (H, 1) and np.abs(U).sum() * p.dt == pytest.approx(0.92, abs=1e-6)


def _tiny(target, deadline=3, eps=0.01) -> ReachMILP:
    """Three steps of 0.5 s at 0.2 m/s: each step moves -0.1, 0 or +0.1 m per axis on the grid."""
    H = 3
    W = np.zeros((1, H))
    W[0, :deadline] = 1
    return ReachMILP(np.zeros(3), np.tile(target, (H, 1)), W, np.ones(1), 0.5, 0.2, eps)


def _grid_best(p: ReachMILP, levels: int = 3) -> float:
    """The cheapest input sequence from ``levels`` values per axis and step that meets the
    window, by evaluating every one (27^3 sequences for three steps)."""
    axis = np.linspace(-p.u_max, p.u_max, levels)
    per_step = np.array(list(itertools.product(axis, repeat=3)))  # (levels^3, 3)
    idx = np.array(list(itertools.product(range(len(per_step)), repeat=p.horizon)))
    U = per_step[idx]  # (N, H, 3)
    x = p.x0 + np.cumsum(U * p.dt, axis=1)
    gap = np.abs(x - p.target).sum(axis=2)
    (w,) = _required_windows(p)
    ok = (gap[:, w] < p.eps).any(axis=1)
    return float(np.abs(U[ok]).sum(axis=(1, 2)).min()) if ok.any() else np.inf


@pytest.mark.parametrize(
    "target",
    [[0.1, -0.1, 0.0], [0.2, 0.1, -0.1], [0.0, 0.0, 0.3], [0.1, 0.1, 0.1]],
)
def test_no_grid_input_beats_the_milp_on_a_tiny_instance(target):
    p = _tiny(np.array(target, float))
    U, status = solve_reach_milp(p)
    assert status == "optimal" and _robustness(p, U) >= -TOL
    grid = _grid_best(p)
    cost = float(np.abs(U).sum())
    assert cost <= grid + TOL
    # The grid holds the exact arrival; the MILP may stop eps short of it (l1), saving eps/dt.
    assert cost == pytest.approx(grid - p.eps / p.dt, abs=1e-5)


def test_a_window_out_of_reach_is_infeasible_for_the_milp_and_the_reference():
    p = _tiny(np.array([0.2, 0.2, 0.0]), deadline=1)  # 0.1 m per axis per step at most
    assert solve_reach_milp(p)[0] is None and _reference_optimum(p) is None
    assert _grid_best(p) == np.inf
    assert independent_discrepancies(p) == []


def test_unreachable_window_is_infeasible_for_both_solvers():
    p = _problem(np.random.default_rng(0), deadline=1)
    p = ReachMILP(p.x0, np.tile([1.5, 0, 0], (6, 1)), p.windows, p.required, 0.2, 1.0, 0.009)
    assert solve_reach_milp(p)[0] is None
    assert solve_reach_milp_cvxpy(p)[0] is None


@pytest.mark.parametrize("seed", [0, 1])
def test_direct_milp_matches_cvxpy_on_the_optimum(seed):
    p = _problem(np.random.default_rng(seed))
    U, _ = solve_reach_milp(p)
    V, _ = solve_reach_milp_cvxpy(p)
    assert np.abs(U).sum() == pytest.approx(np.abs(V).sum(), rel=1e-3, abs=1e-6)


# ------------------------------------------------------------ deliberately broken encodings
def _far_still_target() -> ReachMILP:
    """0.8 m away along x, one window over all six 0.2 s steps at 1 m/s: reachable at x_4."""
    H = 6
    W = np.ones((1, H))
    return ReachMILP(np.zeros(3), np.tile([0.8, 0, 0], (H, 1)), W, np.ones(1), 0.2, 1.0, 0.009)


def _approaching_target() -> ReachMILP:
    """A target coming toward the robot: the later the near step, the cheaper; the window
    closes at x_4."""
    H = 6
    W = np.zeros((1, H))
    W[0, :4] = 1
    target = np.array([[0.7 - 0.05 * j, 0.1, 0.0] for j in range(1, H + 1)])
    return ReachMILP(np.zeros(3), target, W, np.ones(1), 0.2, 1.0, 0.009)


def test_a_too_small_big_m_is_caught_though_the_cvxpy_twin_agrees_with_it(monkeypatch):
    """A big-M ten times too small binds the steps that need not be near (here x_1, 0.6 m short
    of the target at best): the broken MILP finds no plan where the disjunctive LP has one. The
    cvxpy twin shares ``big_m`` and agrees with the broken MILP."""
    p = _far_still_target()
    assert independent_discrepancies(p) == []
    true_big_m = ReachMILP.big_m
    monkeypatch.setattr(ReachMILP, "big_m", lambda self: 0.1 * true_big_m(self))
    assert any("but the optimum is" in f for f in independent_discrepancies(p))
    assert solve_reach_milp(p)[0] is None and solve_reach_milp_cvxpy(p)[0] is None


def test_a_window_read_one_step_late_is_caught():
    """An index slip (``b_j`` taken for ``x_{j+1}``): the slipped MILP meets the target at x_5,
    cheaper and after the window closed; the direct robustness shows the miss."""
    p = _approaching_target()
    assert independent_discrepancies(p) == []

    def slipped(q: ReachMILP):
        return solve_reach_milp(replace(q, windows=np.roll(q.windows, 1, axis=1)))

    assert any("misses a window" in f for f in independent_discrepancies(p, slipped))


def test_a_dropped_window_constraint_is_caught():
    p = _problem(np.random.default_rng(2))

    def dropped(q: ReachMILP):
        return solve_reach_milp(replace(q, required=np.zeros_like(q.required)))

    assert any("misses a window" in f for f in independent_discrepancies(p, dropped))
