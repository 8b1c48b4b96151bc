"""``kl_directions: seed``, eqs. 5.5/5.6 as printed: the policy step's KL(p || pi) (weights and
covariance from the policy's side) and the trajectory step's KL(pi || p) (its covariance solved
exactly), on matrices and a double integrator small enough to check by hand."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("sklearn", reason="the GMM prior needs the optional extra gazebot[gps]")

from gazebot.apps.gps.badmm import policy_targets, seed_policy_cov  # noqa: E402
from gazebot.apps.gps.config import load_gps_config  # noqa: E402
from gazebot.apps.gps.cost import ReachCost  # noqa: E402
from gazebot.apps.gps.dynamics import fit_dynamics  # noqa: E402
from gazebot.apps.gps.lingauss import LinearGaussian  # noqa: E402
from gazebot.apps.gps.lqg import (  # noqa: E402
    NotPositiveDefinite,
    PolicyLinearization,
    forward,
    kl_per_step,
    lqg_update,
    seed_covariance,
)

T, DX, DU = 12, 4, 2


def _spd(rng: np.random.Generator, n: int, floor: float = 0.2) -> np.ndarray:
    a = rng.standard_normal((n, n))
    return a @ a.T + floor * np.eye(n)


def _objective(c: np.ndarray, b: np.ndarray, s: np.ndarray, eta: float, nu: float) -> float:
    """1/2 tr(B C) - eta/2 log det C + nu/2 (tr(C^-1 S) + log det C)."""
    logdet = np.linalg.slogdet(c)[1]
    return 0.5 * np.trace(b @ c) - 0.5 * eta * logdet + 0.5 * nu * (
        np.trace(np.linalg.solve(c, s)) + logdet)


@pytest.mark.parametrize("eta,nu", [(0.9, 0.1), (0.3, 0.7), (0.5, 0.5)])
def test_seed_covariance_is_the_minimiser_of_cost_entropy_and_kl_pi_p(eta, nu):
    rng = np.random.default_rng(4)
    n = 3
    w, s = _spd(rng, n), _spd(rng, n)
    quu = _spd(rng, n) + nu * w  # Q_uu holds the mean term's nu W
    c = seed_covariance(quu, w, s, eta, nu)
    b = quu - nu * w
    p = np.linalg.inv(c)
    # Stationarity: 1/2 B - eta/2 P + nu/2 (P - P S P) = 0.
    np.testing.assert_allclose(0.5 * b - 0.5 * eta * p + 0.5 * nu * (p - p @ s @ p), 0.0,
                               atol=1e-10)
    assert np.linalg.eigvalsh(c).min() > 0
    best = _objective(c, b, s, eta, nu)
    for _ in range(20):  # any nearby covariance does worse
        d = 0.05 * rng.standard_normal((n, n))
        other = c + 0.5 * (d + d.T)
        if np.linalg.eigvalsh(other).min() > 0:
            assert _objective(other, b, s, eta, nu) > best


def test_seed_covariance_without_the_policy_term_is_the_max_entropy_lqr_one():
    rng = np.random.default_rng(5)
    quu, w, s = _spd(rng, 2), _spd(rng, 2), _spd(rng, 2)
    np.testing.assert_allclose(seed_covariance(quu, w, s, 1.0, 0.0), np.linalg.inv(quu),
                               rtol=1e-10)


def test_seed_covariance_refuses_an_indefinite_remainder():
    with pytest.raises(NotPositiveDefinite):
        seed_covariance(np.eye(2), 2.0 * np.eye(2), np.eye(2), 0.5, 0.5)


def test_seed_policy_step_weights_by_the_policys_precision_and_shifts_by_its_covariance():
    rng = np.random.default_rng(6)
    K = rng.standard_normal((T, DU, DX))
    ctrl = LinearGaussian(K, rng.standard_normal((T, DU)),
                          np.broadcast_to(np.diag([2.0, 0.5]), (T, DU, DU)).copy())
    X = rng.standard_normal((5, T, DX))
    lam = rng.standard_normal((T, DU))
    nu = np.linspace(0.2, 2.0, T)
    sigma_pi = np.array([[0.3, 0.05], [0.05, 0.8]])
    target, weight = policy_targets(ctrl, X, lam, nu, sigma_pi)
    for m, t in ((0, 0), (4, T - 1)):
        mu_p = K[t] @ X[m, t] + ctrl.k[t]
        np.testing.assert_allclose(weight[t], nu[t] * np.linalg.inv(sigma_pi), rtol=1e-12)
        np.testing.assert_allclose(target[m, t], mu_p - sigma_pi @ lam[t] / nu[t], rtol=1e-10)
        # The target minimises nu/2 (mu - mu_p)' Sigma_pi^-1 (mu - mu_p) + mu' lambda.
        np.testing.assert_allclose(weight[t] @ (target[m, t] - mu_p) + lam[t], 0.0, atol=1e-10)


class _ConstantPolicy:
    def __init__(self, u: np.ndarray):
        self.u = u

    def mean(self, x: np.ndarray) -> np.ndarray:
        return np.broadcast_to(self.u, x.shape[:-1] + self.u.shape)


def _kl_p_pi(ctrls, Xs, policy, cov) -> float:
    """sum over conditions, samples and steps of KL(p(u|x) || N(policy(x), cov))."""
    prec = np.linalg.inv(cov)
    total = 0.0
    for ctrl, X in zip(ctrls, Xs, strict=True):
        d = np.einsum("tux,mtx->mtu", ctrl.K, X) + ctrl.k - policy.mean(X)
        for t in range(ctrl.horizon):
            c = ctrl.cov[t]
            tr = np.trace(prec @ c) - DU + np.linalg.slogdet(cov)[1] - np.linalg.slogdet(c)[1]
            total += 0.5 * sum(tr + dm @ prec @ dm for dm in d[:, t])
    return total


def test_seed_policy_covariance_minimises_the_summed_kl_p_pi():
    rng = np.random.default_rng(7)
    ctrls = [LinearGaussian(rng.standard_normal((T, DU, DX)), rng.standard_normal((T, DU)),
                            np.array([_spd(rng, DU) for _ in range(T)])) for _ in range(2)]
    Xs = rng.standard_normal((2, 4, T, DX))
    policy = _ConstantPolicy(np.array([0.3, -0.2]))
    cov = seed_policy_cov(ctrls, Xs, policy)
    best = _kl_p_pi(ctrls, Xs, policy, cov)
    mean_prec_inv = np.linalg.inv(np.mean([c.precision for c in ctrls], axis=(0, 1)))
    for other in (1.2 * cov, 0.8 * cov, cov + 0.1 * np.eye(DU), mean_prec_inv):
        assert _kl_p_pi(ctrls, Xs, policy, other) > best


def _double_integrator_problem():
    rng = np.random.default_rng(8)
    A = np.eye(DX)
    A[0, 2] = A[1, 3] = 0.1
    B = np.zeros((DX, DU))
    B[2, 0] = B[3, 1] = 0.1
    prev = LinearGaussian(np.zeros((T, DU, DX)), np.zeros((T, DU)),
                          np.broadcast_to(np.eye(DU), (T, DU, DU)).copy())
    X = np.zeros((20, T, DX))
    U = np.zeros((20, T, DU))
    X[:, 0] = np.array([1.0, -0.5, 0.0, 0.0]) + 0.3 * rng.standard_normal((20, DX))
    for i in range(20):
        for t in range(T):
            U[i, t] = prev.act(t, X[i, t], rng.standard_normal(DU))
            if t + 1 < T:
                X[i, t + 1] = A @ X[i, t] + B @ U[i, t] + 1e-4 * rng.standard_normal(DX)
    sel = np.zeros((3, DX))
    sel[0, 0] = sel[1, 1] = 1.0
    Cm, cv = ReachCost(sel, 1e-5, np.full(DU, 1e-2)).expand(X, U)
    return fit_dynamics(X, U, None, 1.0), Cm, cv, prev


def test_seed_trajectory_step_is_pulled_to_the_policy_by_nu_within_the_step_bound():
    dyn, Cm, cv, prev = _double_integrator_problem()
    pol = PolicyLinearization(np.zeros((T, DU, DX)), np.full((T, DU), 3.0),
                              np.broadcast_to(0.5 * np.eye(DU), (T, DU, DU)).copy())
    lam = np.zeros((T, DU))
    kls = []
    for nu in (0.01, 1.0, 100.0):
        ctrl, _, step = lqg_update(dyn, Cm, cv, prev, pol, np.full(T, nu), lam, 5.0,
                                   seed_directions=True)
        assert step <= 5.0 + 1e-9
        mu, sig = forward(dyn, ctrl)
        kls.append(kl_per_step(mu, sig, pol, ctrl).mean())  # KL(pi || p), the penalised one
    assert kls[0] > kls[1] > kls[2]
    # The two directions give different controllers for the same problem.
    levine, _, _ = lqg_update(dyn, Cm, cv, prev, pol, np.full(T, 1.0), lam, 5.0)
    seed, _, _ = lqg_update(dyn, Cm, cv, prev, pol, np.full(T, 1.0), lam, 5.0,
                            seed_directions=True)
    assert not np.allclose(levine.cov, seed.cov)


def test_the_shipped_configuration_keeps_levine_et_als_directions():
    assert load_gps_config().gps.kl_directions == "levine"


def test_the_seed_directions_inner_loop_sets_the_policy_covariance_from_kl_p_pi():
    pytest.importorskip("jax", reason="the global policy needs the optional extra gazebot[gps]")
    from gazebot.apps.gps.badmm import inner_loop
    from tests.apps.gps.test_gps_badmm import _config, _problem, _state

    cfg = _config(kl_directions="seed")
    Xs, dyns, expansions, ctrls = _problem()
    st = _state(cfg, ctrls)
    inner_loop(cfg, st, Xs, dyns, expansions, iteration=0)
    # The policy step saw the sampling controllers; its covariance is eq. 5.5's minimiser,
    # not the Levine inverse mean precision (0.25 I here).
    np.testing.assert_allclose(st.policy.cov, seed_policy_cov(ctrls, Xs, st.policy), rtol=1e-9)
    assert not np.allclose(st.policy.cov, 0.25 * np.eye(DU))
    assert np.abs(st.lam).max() > 0
    assert all(np.all(np.isfinite(c.K)) and np.all(np.linalg.eigvalsh(c.cov) > 0)
               for c in st.controllers)
