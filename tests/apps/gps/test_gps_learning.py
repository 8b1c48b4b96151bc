"""The GPS pieces on problems small enough to check exactly: eq. 5.11's cost and its expansion,
eq. 5.3's regression with its GMM prior, the LQG step with its KL terms (eq. 5.6) and the
policy's supervised fit (eq. 5.5)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("sklearn", reason="the GMM prior needs the optional extra gazebot[gps]")

from gazebot.apps.gps.cost import ReachCost  # noqa: E402
from gazebot.apps.gps.dynamics import GMMPrior, fit_dynamics, transitions  # noqa: E402
from gazebot.apps.gps.lingauss import LinearGaussian  # noqa: E402
from gazebot.apps.gps.lqg import PolicyLinearization, forward, kl_per_step, lqg_update  # noqa: E402
from gazebot.apps.gps.policy import init_policy, jacobians, train_policy  # noqa: E402

T, DX, DU = 15, 4, 2


def _double_integrator(dt: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    A = np.eye(DX)
    A[0, 2] = A[1, 3] = dt
    B = np.zeros((DX, DU))
    B[2, 0] = B[3, 1] = dt
    return A, B


def _rollouts(ctrl: LinearGaussian, n: int, rng: np.random.Generator, noise: float = 1e-4):
    A, B = _double_integrator()
    X = np.zeros((n, T, DX))
    U = np.zeros((n, T, DU))
    X[:, 0] = np.array([1.0, -0.5, 0.0, 0.0]) + 0.3 * rng.standard_normal((n, DX))
    for i in range(n):
        for t in range(T):
            U[i, t] = ctrl.act(t, X[i, t], rng.standard_normal(DU))
            if t + 1 < T:
                X[i, t + 1] = A @ X[i, t] + B @ U[i, t] + noise * rng.standard_normal(DX)
    return X, U


def _zero_controller(std: float = 1.0) -> LinearGaussian:
    return LinearGaussian(np.zeros((T, DU, DX)), np.zeros((T, DU)),
                          np.broadcast_to(np.eye(DU) * std**2, (T, DU, DU)).copy())


def _cost() -> ReachCost:
    sel = np.zeros((3, DX))
    sel[0, 0] = sel[1, 1] = 1.0  # the "gap" is the position, the target the origin
    return ReachCost(sel, 1e-5, np.full(DU, 1e-2))


def _expected_cost(cost: ReachCost, dyn, ctrl: LinearGaussian) -> float:
    mu, _ = forward(dyn, ctrl)
    U = np.einsum("tux,tx->tu", ctrl.K, mu) + ctrl.k
    return float(cost.total(mu, U).sum())


def test_reach_cost_is_eq_5_11_and_its_expansion_has_the_cost_gradient():
    cost = _cost()
    x = np.array([0.3, -0.4, 1.0, 2.0])
    assert cost.reach(x) == pytest.approx(0.25 + np.log(0.25 + 1e-5))
    X = x[None, None]
    U = np.array([[[0.5, -1.0]]])
    Cm, cv = cost.expand(X, U)
    xu = np.r_[x, U[0, 0]]
    grad = Cm[0] @ xu + cv[0]
    eps = 1e-6
    fd = [(cost.total(*(np.split(xu + eps * e, [DX])))
           - cost.total(*(np.split(xu - eps * e, [DX])))) / (2 * eps) for e in np.eye(DX + DU)]
    np.testing.assert_allclose(grad, fd, rtol=1e-5)
    assert np.all(np.linalg.eigvalsh(Cm[0]) >= -1e-12)  # kept positive semi-definite


def test_dynamics_regression_recovers_a_linear_system_and_the_prior_fills_in_few_samples():
    rng = np.random.default_rng(0)
    A, B = _double_integrator()
    truth = np.hstack([A, B])
    X, U = _rollouts(_zero_controller(), 30, rng)
    dyn = fit_dynamics(X, U, None, 1.0)
    np.testing.assert_allclose(dyn.Fm, np.broadcast_to(truth, dyn.Fm.shape), atol=0.02)
    # Three samples cannot determine a 6-input regression; the GMM prior fitted on many
    # transitions (eq. 5.3's prior) makes them enough.
    prior = GMMPrior(2)
    prior.fit(transitions(X, U))
    few_X, few_U = X[:3], U[:3]
    with_prior = fit_dynamics(few_X, few_U, prior, 1.0)
    without = fit_dynamics(few_X, few_U, None, 1.0)
    err_with = np.abs(with_prior.Fm - truth).mean()
    err_without = np.abs(without.Fm - truth).mean()
    assert err_with < 0.05 < err_without


def test_lqg_step_lowers_the_cost_within_the_kl_bound():
    rng = np.random.default_rng(1)
    prev = _zero_controller()
    X, U = _rollouts(prev, 20, rng)
    dyn = fit_dynamics(X, U, None, 1.0)
    cost = _cost()
    Cm, cv = cost.expand(X, U)
    zeros_nu, zeros_lam = np.zeros(T), np.zeros((T, DU))
    small, _, kl_small = lqg_update(dyn, Cm, cv, prev, None, zeros_nu, zeros_lam, 0.05)
    large, _, kl_large = lqg_update(dyn, Cm, cv, prev, None, zeros_nu, zeros_lam, 2.0)
    assert kl_small <= 0.05 + 1e-9 and kl_large <= 2.0 + 1e-9
    assert kl_small < kl_large
    c0 = _expected_cost(cost, dyn, prev)
    c_small = _expected_cost(cost, dyn, small)
    c_large = _expected_cost(cost, dyn, large)
    assert c_large < c_small < c0
    mu, sig = forward(dyn, small)
    assert kl_per_step(mu, sig, small, prev).mean() == pytest.approx(kl_small)


def test_kl_weight_nu_pulls_the_local_controller_to_the_policy_and_lambda_shifts_its_action():
    rng = np.random.default_rng(2)
    prev = _zero_controller()
    X, U = _rollouts(prev, 20, rng)
    dyn = fit_dynamics(X, U, None, 1.0)
    Cm, cv = _cost().expand(X, U)
    pol = PolicyLinearization(np.zeros((T, DU, DX)), np.full((T, DU), 3.0),
                              np.broadcast_to(np.eye(DU), (T, DU, DU)).copy())
    lam0 = np.zeros((T, DU))
    kls = []
    for nu in (0.01, 1.0, 100.0):
        ctrl, _, _ = lqg_update(dyn, Cm, cv, prev, pol, np.full(T, nu), lam0, 5.0)
        mu, sig = forward(dyn, ctrl)
        kls.append(kl_per_step(mu, sig, ctrl, pol).mean())
    assert kls[0] > kls[1] > kls[2]
    # Eq. 5.6's -u' lambda: a positive multiplier raises the local controller's action.
    nu = np.full(T, 1.0)
    base, _, _ = lqg_update(dyn, Cm, cv, prev, pol, nu, lam0, 5.0)
    lam = np.zeros((T, DU))
    lam[:, 0] = 0.5
    shifted, _, _ = lqg_update(dyn, Cm, cv, prev, pol, nu, lam, 5.0)
    x0 = dyn.x0_mu
    assert shifted.mean(0, x0)[0] > base.mean(0, x0)[0]


def test_policy_network_imitates_a_linear_controller_and_its_jacobian_is_exact():
    pytest.importorskip("jax", reason="the policy network needs the optional extra gazebot[gps]")
    rng = np.random.default_rng(3)
    dx, du = 6, 3
    K = rng.standard_normal((du, dx))
    k = rng.standard_normal(du)
    X = rng.standard_normal((600, dx))
    target = X @ K.T + k
    W = np.broadcast_to(np.eye(du), (600, du, du)).copy()
    params = init_policy(dx, du, 84, np.full(du, 5.0), 0)
    before = np.mean((params.mean(X) - target) ** 2)
    trained = train_policy(params, X, target, W, 1500, 128, 3e-3, 0)
    after = np.mean((trained.mean(X) - target) ** 2)
    assert after < 0.02 * before
    J = jacobians(trained, X[:5])
    eps = 1e-6
    for i in range(5):
        fd = np.array([(trained.mean(X[i] + eps * e) - trained.mean(X[i] - eps * e)) / (2 * eps)
                       for e in np.eye(dx)]).T
        np.testing.assert_allclose(J[i], fd, atol=1e-5)


def test_a_feature_constant_in_training_is_not_amplified_when_it_moves():
    from gazebot.apps.gps.policy import input_scale

    scale = input_scale(np.array([0.0, 1e-4, 0.2]))
    np.testing.assert_allclose(scale, [1.0, 1e-3, 0.2])
