"""The BADMM core on a double integrator (4 states, 2 actions): eq. 5.5's supervised target, eq.
5.7's dual step as implemented (alpha nu_t Sigma_pi^-1 (E[pi u] - E[p u])), nu_t's adaptation,
and that the multipliers are what pulls the local controllers and the policy together."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

pytest.importorskip("sklearn", reason="the GMM prior needs the optional extra gazebot[gps]")
pytest.importorskip("jax", reason="the global policy needs the optional extra gazebot[gps]")

from gazebot.apps.gps import badmm  # noqa: E402
from gazebot.apps.gps.badmm import (  # noqa: E402
    GPSState,
    adapt_nu,
    dual_step,
    inner_loop,
    policy_targets,
)
from gazebot.apps.gps.config import load_gps_config  # noqa: E402
from gazebot.apps.gps.cost import ReachCost  # noqa: E402
from gazebot.apps.gps.dynamics import fit_dynamics  # noqa: E402
from gazebot.apps.gps.lingauss import LinearGaussian  # noqa: E402
from gazebot.apps.gps.policy import init_policy  # noqa: E402

T, DX, DU, M = 10, 4, 2, 8


def _double_integrator(dt: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    A = np.eye(DX)
    A[0, 2] = A[1, 3] = dt
    B = np.zeros((DX, DU))
    B[2, 0] = B[3, 1] = dt
    return A, B


def _controller(gain: float, offset: np.ndarray, std: float) -> LinearGaussian:
    """u = -gain * position + offset, with exploration std."""
    K = np.zeros((T, DU, DX))
    K[:, 0, 0] = K[:, 1, 1] = -gain
    return LinearGaussian(K, np.broadcast_to(offset, (T, DU)).copy(),
                          np.broadcast_to(np.eye(DU) * std**2, (T, DU, DU)).copy())


def _samples(ctrl: LinearGaussian, x0: np.ndarray, rng: np.random.Generator) -> tuple[
        np.ndarray, np.ndarray]:
    A, B = _double_integrator()
    X = np.zeros((M, T, DX))
    U = np.zeros((M, T, DU))
    X[:, 0] = x0 + 0.05 * rng.standard_normal((M, DX))
    for m in range(M):
        for t in range(T):
            U[m, t] = ctrl.act(t, X[m, t], rng.standard_normal(DU))
            if t + 1 < T:
                X[m, t + 1] = A @ X[m, t] + B @ U[m, t] + 1e-4 * rng.standard_normal(DX)
    return X, U


def _config(**gps):
    cfg = load_gps_config()
    base = dict(inner_iterations=1, policy_steps=300, batch=64, hidden_units=16,
                learning_rate=3e-3, nu_init=0.01, nu_max=10.0, kl_policy_target=1.0,
                dual_rate=0.1, kl_step=1.0, seed=0)
    base.update(gps)
    return cfg.model_copy(update={"gps": cfg.gps.model_copy(update=base)})


def _problem(seed: int = 0):
    """Two conditions (start states) on the double integrator with a reach-to-origin cost,
    their samples, fitted dynamics and cost expansions, and a fresh BADMM state."""
    rng = np.random.default_rng(seed)
    starts = [np.array([1.0, -0.5, 0.0, 0.0]), np.array([-0.8, 0.6, 0.0, 0.0])]
    ctrls = [_controller(2.0, np.array([0.5, -0.5]), 0.5),
             _controller(2.0, np.array([-0.5, 0.5]), 0.5)]
    Xs, dyns, expansions = [], [], []
    sel = np.zeros((3, DX))
    sel[0, 0] = sel[1, 1] = 1.0
    cost = ReachCost(sel, 1e-5, np.full(DU, 1e-2))
    for c, x0 in zip(ctrls, starts, strict=True):
        X, U = _samples(c, x0, rng)
        Xs.append(X)
        dyns.append(fit_dynamics(X, U, None, 1.0))
        expansions.append(cost.expand(X, U))
    return np.array(Xs), dyns, expansions, ctrls


def _state(cfg, ctrls: list[LinearGaussian]) -> GPSState:
    policy = init_policy(DX, DU, cfg.gps.hidden_units, np.full(DU, 5.0), 0)
    return GPSState(list(ctrls), np.zeros((len(ctrls), T, DU)),
                    np.full((len(ctrls), T), cfg.gps.nu_init), policy)


def _disagreement(st: GPSState, Xs: np.ndarray) -> float:
    """Mean distance between the policy's and the local controllers' mean actions at the samples."""
    out = []
    for ctrl, X in zip(st.controllers, Xs, strict=True):
        mu_p = np.einsum("tux,mtx->mtu", ctrl.K, X) + ctrl.k
        out.append(np.linalg.norm(st.policy.mean(X) - mu_p, axis=-1).mean())
    return float(np.mean(out))


def test_eq_5_5_target_is_the_local_mean_shifted_by_the_multiplier_over_nu():
    rng = np.random.default_rng(1)
    ctrl = _controller(1.5, np.array([0.2, -0.1]), 1.0)
    ctrl = LinearGaussian(ctrl.K, ctrl.k, np.broadcast_to(np.array([[2.0, 0.3], [0.3, 0.5]]),
                                                          (T, DU, DU)).copy())
    X = rng.standard_normal((M, T, DX))
    lam = rng.standard_normal((T, DU))
    nu = np.linspace(0.1, 2.0, T)
    target, weight = policy_targets(ctrl, X, lam, nu)
    for m, t in ((0, 0), (3, 7), (M - 1, T - 1)):
        mu_p = ctrl.K[t] @ X[m, t] + ctrl.k[t]
        np.testing.assert_allclose(target[m, t], mu_p - ctrl.cov[t] @ lam[t] / nu[t], rtol=1e-12)
        np.testing.assert_allclose(weight[t], nu[t] * np.linalg.inv(ctrl.cov[t]), rtol=1e-12)
        # The target minimises nu/2 (mu - mu_p)' C^-1 (mu - mu_p) + mu' lambda: zero gradient.
        grad = weight[t] @ (target[m, t] - mu_p) + lam[t]
        np.testing.assert_allclose(grad, 0.0, atol=1e-12)


def test_one_dual_step_changes_lambda_by_alpha_nu_sigma_pi_inverse_times_the_action_gap():
    rng = np.random.default_rng(2)
    lam = rng.standard_normal((T, DU))
    nu = np.linspace(0.5, 3.0, T)
    mu_pi = rng.standard_normal((M, T, DU))
    mu_p = rng.standard_normal((M, T, DU))
    cov = np.array([[0.5, 0.1], [0.1, 0.2]])
    new = dual_step(lam, nu, mu_pi, mu_p, cov, 0.1)
    expected = lam + 0.1 * nu[:, None] * ((mu_pi - mu_p).mean(axis=0) @ np.linalg.inv(cov))
    np.testing.assert_allclose(new, expected, rtol=1e-12)
    # The multiplier grows along the policy's excess: eq. 5.6's -u' lambda then raises p's action
    # and eq. 5.5's target lowers pi's.
    np.testing.assert_allclose(dual_step(np.zeros((T, DU)), nu, mu_p + 1.0, mu_p, np.eye(DU), 0.1),
                               0.1 * nu[:, None] * np.ones((T, DU)), rtol=1e-12)


def test_nu_doubles_where_policy_and_controller_disagree_halves_where_they_agree_and_is_clipped():
    nu = np.array([1.0, 1.0, 1.0, 6.0, 0.02])
    kl = np.array([2.0, 0.5, 0.1, 5.0, 0.0])
    np.testing.assert_allclose(adapt_nu(nu, kl, 1.0, 0.01, 10.0), [2.0, 1.0, 0.5, 10.0, 0.01])


def test_the_inner_loop_applies_eq_5_7_to_the_fitted_policy_and_the_sampling_controllers():
    cfg = _config()
    Xs, dyns, expansions, ctrls = _problem()
    st = _state(cfg, ctrls)
    nu0 = st.nu.copy()
    inner_loop(cfg, st, Xs, dyns, expansions, iteration=0)
    for i, ctrl in enumerate(ctrls):
        mu_p = np.einsum("tux,mtx->mtu", ctrl.K, Xs[i]) + ctrl.k
        gap = (st.policy.mean(Xs[i]) - mu_p).mean(axis=0) @ np.linalg.inv(st.policy.cov).T
        np.testing.assert_allclose(st.lam[i], 0.1 * nu0[i][:, None] * gap, rtol=1e-9)
        assert np.abs(st.lam[i]).max() > 0
    # The policy's covariance is the inverse of the controllers' mean precision (0.5^2 each).
    np.testing.assert_allclose(st.policy.cov, 0.25 * np.eye(DU), rtol=1e-9)


def test_the_multipliers_pull_the_local_controllers_to_the_policy(monkeypatch):
    """BADMM passes on one iteration's samples, the policy held at a constant action (its fit
    stubbed out) and nu_t at its floor, so the KL weight alone barely couples them: with eq. 5.7
    the multipliers grow with every pass and the local controllers' mean action moves to the
    policy's; with lambda held at 0 every pass re-solves the same problem."""
    Xs, dyns, expansions, ctrls = _problem()
    pi_u = np.array([1.5, 1.0])

    def after(passes: int) -> tuple[float, GPSState]:
        cfg = _config(inner_iterations=passes, nu_max=0.01, dual_rate=1.0, kl_step=4.0)
        st = _state(cfg, ctrls)
        p = st.policy
        st.policy = replace(p, w2=np.zeros_like(p.w2), b2=pi_u / p.u_scale,
                            cov=0.01 * np.eye(DU))
        inner_loop(cfg, st, Xs, dyns, expansions, iteration=0)
        return _disagreement(st, Xs), st

    monkeypatch.setattr(badmm, "_update_policy", lambda cfg, st, Xs, seed: None)
    with_dual = [after(n) for n in (1, 2, 4)]
    monkeypatch.setattr(badmm, "dual_step", lambda lam, *args: lam)
    without = [after(n) for n in (1, 2, 4)]

    assert all(np.all(st.lam == 0) for _, st in without)
    assert np.abs(with_dual[-1][1].lam).max() > 0
    d = [x for x, _ in with_dual]
    d0 = [x for x, _ in without]
    # Each pass's accumulated multiplier moves the controllers further towards the policy ...
    assert d[0] > d[1] > d[2]
    # ... while with lambda at 0 the passes repeat the first one.
    np.testing.assert_allclose(d0, d0[0], rtol=1e-9)
    assert d[-1] < d0[-1], (d, d0)
