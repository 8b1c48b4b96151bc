"""LQG trajectory optimization of one local controller with the BADMM terms (eqs. 5.6-5.7).

The local controller p minimises E_p[l(x, u) - u' lambda_t] + nu_t KL(p || pi_lin) subject to
KL(p || p_prev) <= kl_step per step, where pi_lin = N(K_bar x + k_bar, S_bar) is the global policy
linearised along the samples and p_prev the controller that produced the samples. With Lagrange
multiplier eta on the step bound this is an LQR on the cost

    (l - u' lambda + eta (-log p_prev) + nu (-log pi_lin)) / (eta + nu),

whose maximum-entropy solution has C_t = Q_uu^-1. eta is found by bisection.

Two departures from the seed's eq. 5.6, as in Levine et al.'s BADMM GPS (the seed's [92]): the
policy term is nu_t KL(p || pi_lin), where eq. 5.6 writes nu_t KL(pi_theta || p); and the step
bound KL(p || p_prev) <= kl_step is added (eq. 5.6 has none). The README's "where we differ"
says why.

With ``seed_directions`` the policy term is eq. 5.6's as printed, nu_t E_p(x)[KL(pi_lin || p)]
= nu_t/2 E[tr(C_t^-1 S_t) + (mu_p - mu_pi)' C_t^-1 (mu_p - mu_pi) + log det C_t] + const. Its mean
part is weighted by the new controller's own precision C_t^-1, which no LQR can hold; we weight
it by the sampled controller's precision (exact when the step leaves C_t unchanged) and solve
the covariance exactly (:func:`seed_covariance`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gazebot.apps.gps.dynamics import LinearDynamics
from gazebot.apps.gps.lingauss import LinearGaussian


class NotPositiveDefinite(np.linalg.LinAlgError):
    """Q_uu lost positive definiteness: the KL weight eta must grow."""


@dataclass(frozen=True)
class PolicyLinearization:
    """The global policy around one condition's samples:
    K (T, dU, dX), k (T, dU), cov (T, dU, dU)."""

    K: np.ndarray
    k: np.ndarray
    cov: np.ndarray


def _kl_quadratic(K: np.ndarray, k: np.ndarray, prec: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """-log N(u; K x + k, P^-1) up to a constant, as (1/2 xu' M xu + v' xu): (M, v)."""
    M = np.block([[K.T @ prec @ K, -K.T @ prec], [-prec @ K, prec]])
    v = np.concatenate([K.T @ prec @ k, -prec @ k])
    return M, v


def seed_covariance(quu: np.ndarray, w: np.ndarray, s: np.ndarray, eta: float,
                    nu: float) -> np.ndarray:
    """The controller covariance C minimising, per step (in the units of Q / (eta + nu)),

        1/2 tr((Q_uu - nu W) C) - eta/2 log det C + nu/2 (tr(C^-1 S) + log det C),

    i.e. the expected cost, eta KL(p || p_prev)'s entropy part and eq. 5.6's nu KL(pi || p)'s
    covariance part (S the policy's covariance; nu W is the mean-term weight that Q_uu holds,
    whose tr(W C) the literal KL does not have). Stationarity, with P = C^-1 and
    B = Q_uu - nu W, is nu P S P + (eta - nu) P - B = 0; with Y = S^1/2 P S^1/2 it is a scalar
    quadratic per eigenvalue g of S^1/2 B S^1/2, whose positive root is
    y = 2 g / ((eta - nu) + sqrt((eta - nu)^2 + 4 nu g)). Raises :class:`NotPositiveDefinite`
    where B is not positive definite (eta must grow)."""
    b = quu - nu * w
    ev, vec = np.linalg.eigh(0.5 * (s + s.T))
    if ev.min() <= 0:
        raise NotPositiveDefinite("policy covariance not positive definite")
    s_half = (vec * np.sqrt(ev)) @ vec.T
    g, gv = np.linalg.eigh(s_half @ (0.5 * (b + b.T)) @ s_half)
    if g.min() <= 0:
        raise NotPositiveDefinite("Q_uu - nu W not positive definite")
    d = eta - nu
    y = 2.0 * g / (d + np.sqrt(d * d + 4.0 * nu * g))
    cov = s_half @ (gv / y) @ gv.T @ s_half  # C = S^1/2 Y^-1 S^1/2
    return 0.5 * (cov + cov.T)


def backward(dyn: LinearDynamics, Cm: np.ndarray, cv: np.ndarray, prev: LinearGaussian,
             pol: PolicyLinearization | None, nu: np.ndarray, lam: np.ndarray,
             eta: float, seed_directions: bool = False) -> LinearGaussian:
    """One LQR backward pass for the combined cost; raises :class:`NotPositiveDefinite`.

    ``seed_directions``: the policy term is nu KL(pi_lin || p) (eq. 5.6 as printed), its mean
    part weighted by ``prev``'s precision, the covariance from :func:`seed_covariance`."""
    horizon, du, dx = prev.K.shape
    K = np.zeros_like(prev.K)
    k = np.zeros_like(prev.k)
    cov = np.zeros_like(prev.cov)
    Vxx = np.zeros((dx, dx))
    Vx = np.zeros(dx)
    prev_prec = np.linalg.inv(prev.cov)
    pol_prec = np.linalg.inv(pol.cov) if pol is not None else None
    if seed_directions and pol_prec is not None:
        pol_prec = prev_prec  # the mean part of KL(pi || p) is weighted by p's precision
    for t in range(horizon - 1, -1, -1):
        M, v = _kl_quadratic(prev.K[t], prev.k[t], prev_prec[t])
        w = nu[t] if pol is not None else 0.0
        c_m = Cm[t] + eta * M
        c_v = cv[t].copy()
        c_v[dx:] -= lam[t]
        c_v += eta * v
        if pol is not None and pol_prec is not None:
            pm, pv = _kl_quadratic(pol.K[t], pol.k[t], pol_prec[t])
            c_m = c_m + w * pm
            c_v = c_v + w * pv
        Q = c_m / (eta + w)
        q = c_v / (eta + w)
        if t < horizon - 1:
            F, f = dyn.Fm[t], dyn.fv[t]
            Q = Q + F.T @ Vxx @ F
            q = q + F.T @ (Vx + Vxx @ f)
        Q = 0.5 * (Q + Q.T)
        Quu, Qux, qu = Q[dx:, dx:], Q[dx:, :dx], q[dx:]
        try:
            L = np.linalg.cholesky(Quu)
        except np.linalg.LinAlgError as exc:
            raise NotPositiveDefinite(f"Q_uu not positive definite at t={t}") from exc
        inv_quu = np.linalg.solve(L.T, np.linalg.solve(L, np.eye(du)))
        K[t] = -inv_quu @ Qux
        k[t] = -inv_quu @ qu
        if seed_directions and pol is not None:
            total = eta + w
            cov[t] = seed_covariance(Quu, prev_prec[t], pol.cov[t], eta / total, w / total)
        else:
            cov[t] = 0.5 * (inv_quu + inv_quu.T)
        Vxx = Q[:dx, :dx] + Q[:dx, dx:] @ K[t]
        Vxx = 0.5 * (Vxx + Vxx.T)
        Vx = q[:dx] + Q[:dx, dx:] @ k[t]
    return LinearGaussian(K, k, cov)


def forward(dyn: LinearDynamics, ctrl: LinearGaussian) -> tuple[np.ndarray, np.ndarray]:
    """State means (T, dX) and covariances (T, dX, dX) of ``ctrl`` under ``dyn``."""
    horizon, du, dx = ctrl.K.shape
    mu = np.zeros((horizon, dx))
    sig = np.zeros((horizon, dx, dx))
    mu[0], sig[0] = dyn.x0_mu, dyn.x0_cov
    for t in range(horizon - 1):
        K = ctrl.K[t]
        mu_u = K @ mu[t] + ctrl.k[t]
        s_xu = np.block([[sig[t], sig[t] @ K.T], [K @ sig[t], K @ sig[t] @ K.T + ctrl.cov[t]]])
        F = dyn.Fm[t]
        mu[t + 1] = F @ np.concatenate([mu[t], mu_u]) + dyn.fv[t]
        s = F @ s_xu @ F.T + dyn.cov[t]
        sig[t + 1] = 0.5 * (s + s.T)
    return mu, sig


def kl_per_step(mu: np.ndarray, sig: np.ndarray, new: LinearGaussian | PolicyLinearization,
                old: LinearGaussian | PolicyLinearization) -> np.ndarray:
    """E_{x ~ N(mu_t, sig_t)} KL(new(u|x) || old(u|x)) for each t."""
    horizon, du, _ = new.K.shape
    out = np.zeros(horizon)
    for t in range(horizon):
        p_old = np.linalg.inv(old.cov[t])
        dK = new.K[t] - old.K[t]
        dk = dK @ mu[t] + new.k[t] - old.k[t]
        _, logdet_old = np.linalg.slogdet(old.cov[t])
        _, logdet_new = np.linalg.slogdet(new.cov[t])
        out[t] = 0.5 * (np.trace(p_old @ new.cov[t]) + dk @ p_old @ dk
                        + np.trace(dK.T @ p_old @ dK @ sig[t]) - du + logdet_old - logdet_new)
    return np.maximum(out, 0.0)


def lqg_update(dyn: LinearDynamics, Cm: np.ndarray, cv: np.ndarray, prev: LinearGaussian,
               pol: PolicyLinearization | None, nu: np.ndarray, lam: np.ndarray,
               kl_step: float, eta_bounds: tuple[float, float] = (1e-6, 1e16),
               iterations: int = 30,
               seed_directions: bool = False) -> tuple[LinearGaussian, float, float]:
    """The new local controller with mean KL(new || prev) <= ``kl_step`` (eq. 5.6), by bisection
    on log(eta). Returns (controller, eta, achieved mean KL). ``seed_directions``: see
    :func:`backward`."""
    lo, hi = np.log(eta_bounds[0]), np.log(eta_bounds[1])

    def solve(log_eta: float) -> tuple[LinearGaussian, float] | None:
        try:
            ctrl = backward(dyn, Cm, cv, prev, pol, nu, lam, float(np.exp(log_eta)),
                            seed_directions)
        except NotPositiveDefinite:
            return None
        mu, sig = forward(dyn, ctrl)
        kl = float(kl_per_step(mu, sig, ctrl, prev).mean())
        return (ctrl, kl) if np.isfinite(kl) else None

    first = solve(lo)
    if first is not None and first[1] <= kl_step:
        return first[0], float(np.exp(lo)), first[1]
    best = None
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        res = solve(mid)
        if res is None or res[1] > kl_step:
            lo = mid
        else:
            hi = mid
            best = (res[0], float(np.exp(mid)), res[1])
            if res[1] > 0.9 * kl_step:
                break
    if best is None:
        res = solve(hi)
        if res is None:
            return prev, float(np.exp(hi)), 0.0
        best = (res[0], float(np.exp(hi)), res[1])
    return best
