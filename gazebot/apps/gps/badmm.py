"""BADMM Guided Policy Search (seed section 5.2.1; Levine et al.'s algorithm, which the seed uses).

Each iteration: sample every local controller (eq. 5.2) on its training target; fit each
condition's linear-Gaussian dynamics with the shared GMM prior (eq. 5.3); then alternate
``inner_iterations`` times between the global policy's supervised update (eq. 5.5), the dual update
of the Lagrange multipliers on the expected action (eq. 5.7), the adaptation of the KL weights
nu_t, and the local controllers' LQG update (eq. 5.6) under a KL step bound.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from threadpoolctl import threadpool_limits

from gazebot.apps.gps.config import GPSFileConfig
from gazebot.apps.gps.cost import ReachCost
from gazebot.apps.gps.dynamics import GMMPrior, LinearDynamics, fit_dynamics, transitions
from gazebot.apps.gps.lingauss import LinearGaussian, pd_controller
from gazebot.apps.gps.lqg import PolicyLinearization, kl_per_step, lqg_update
from gazebot.apps.gps.policy import PolicyParams, init_policy, jacobians, train_policy
from gazebot.apps.gps.reach_scene import DU, HandoverScene
from gazebot.apps.gps.shell import training_targets
from gazebot.apps.gps.state import DIMS, StateKind, gap_selector, state_vector
from gazebot.apps.gps.tester import TesterMotion, motion_to
from gazebot.apps.gps.trial import Trial, run_trial


@dataclass(frozen=True)
class IterationLog:
    """What one GPS iteration measured (costs are per-trial sums of the eq. 5.11 cost)."""

    iteration: int
    local_cost: float  # mean over conditions and samples, local controllers' samples
    local_error_m: float  # mean final error of those samples
    policy_error_m: float  # mean final error of the global policy on the training targets
    policy_kl: float  # mean E_p KL per step after the update (the direction eq. 5.6 penalises)
    nu_mean: float
    eta_mean: float


@dataclass
class GPSState:
    """The per-condition variables BADMM carries between iterations."""

    controllers: list[LinearGaussian]
    lam: np.ndarray  # (C, T, dU) Lagrange multipliers on the expected action
    nu: np.ndarray  # (C, T) KL weights
    policy: PolicyParams
    log: list[IterationLog] = field(default_factory=list)


@dataclass(frozen=True)
class TrainResult:
    """A run's outcome and everything another run needs to continue it
    (:func:`continue_training`): the BADMM state, the dynamics prior's transition buffer and the
    sampling generator's state."""

    policy: PolicyParams
    state: GPSState
    kind: StateKind
    targets: np.ndarray
    moving: bool
    train_errors_m: np.ndarray  # the global policy's final error per training target
    buffer: list[np.ndarray] = field(default_factory=list)
    rng_state: dict | None = None


def cost_for(cfg: GPSFileConfig, kind: StateKind) -> ReachCost:
    g = cfg.gps
    w_u = np.r_[np.full(DU - 1, g.torque_weight), g.gripper_weight]
    return ReachCost(gap_selector(kind), g.alpha_reach, w_u)


def policy_act(policy: PolicyParams) -> Callable[[int, np.ndarray], np.ndarray]:
    return lambda t, x: policy.mean(x)


def _policy_linearization(policy: PolicyParams, X: np.ndarray) -> PolicyLinearization:
    """Linearise the network at one condition's sample states X (M, T, dX)."""
    m, horizon, dx = X.shape
    du = policy.cov.shape[0]
    flat = X.reshape(-1, dx)
    J = jacobians(policy, flat).reshape(m, horizon, du, dx)
    mu = policy.mean(flat).reshape(m, horizon, du)
    K = J.mean(axis=0)
    k = (mu - np.einsum("mtux,mtx->mtu", J, X)).mean(axis=0)
    cov = np.broadcast_to(policy.cov, (horizon, du, du)).copy()
    return PolicyLinearization(K, k, cov)


def _sample_moments(X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    mu = X.mean(axis=0)
    d = X - mu
    sig = np.einsum("mti,mtj->tij", d, d) / X.shape[0]
    return mu, sig


def policy_targets(ctrl: LinearGaussian, X: np.ndarray, lam: np.ndarray,
                   nu: np.ndarray, policy_cov: np.ndarray | None = None,
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Eq. 5.5's regression for one condition at its sample states X (M, T, dX): the targets
    mu_p(x) - C_t lambda_t / nu_t (M, T, dU) and the weights nu_t C_t^-1 (T, dU, dU).

    They make the loss nu_t/2 (mu - target)' C_t^-1 (mu - target) equal, up to a constant, to
    mu' lambda_t plus the mean part of nu_t KL(pi || p) (the seed writes KL(p || pi); see the
    README's "where we differ"). Given ``policy_cov`` Sigma_pi (dU, dU), the seed's eq. 5.5 as
    printed: the mean part of nu_t KL(p || pi), weights nu_t Sigma_pi^-1, targets
    mu_p - Sigma_pi lambda_t / nu_t."""
    if policy_cov is None:
        prec = ctrl.precision  # (T, dU, dU)
    else:
        prec = np.broadcast_to(np.linalg.inv(policy_cov), ctrl.cov.shape)
    mu_p = np.einsum("tux,mtx->mtu", ctrl.K, X) + ctrl.k
    # nu/2 (mu - mu_p)' P (mu - mu_p) + mu' lam
    #   = nu/2 (mu - (mu_p - P^-1 lam / nu))' P (...) + const
    shift = np.linalg.solve(prec, lam[..., None])[..., 0] / nu[:, None]
    return mu_p - shift, nu[:, None, None] * prec


def _update_policy(cfg: GPSFileConfig, st: GPSState, Xs: np.ndarray, seed: int) -> None:
    """Eq. 5.5's policy step: regress the network on all conditions' samples (see
    :func:`policy_targets`)."""
    g = cfg.gps
    c, m, horizon, dx = Xs.shape
    du = st.lam.shape[-1]
    seed_kl = g.kl_directions == "seed"
    xs, tgts, wts, precs = [], [], [], []
    for i, ctrl in enumerate(st.controllers):
        target, w = policy_targets(ctrl, Xs[i], st.lam[i], st.nu[i],
                                   st.policy.cov if seed_kl else None)
        xs.append(Xs[i].reshape(-1, dx))
        tgts.append(target.reshape(-1, du))
        wts.append(np.broadcast_to(w, (m,) + w.shape).reshape(-1, du, du))
        precs.append(ctrl.precision)
    W = np.concatenate(wts)
    W = W / np.mean(np.trace(W, axis1=1, axis2=2)) * du  # normalised as Levine et al. do
    policy = train_policy(st.policy, np.concatenate(xs), np.concatenate(tgts), W,
                          g.policy_steps, g.batch, g.learning_rate, seed)
    if seed_kl:
        cov = seed_policy_cov(st.controllers, Xs, policy)
    else:
        mean_prec = np.mean(np.concatenate(precs), axis=0)
        cov = np.linalg.inv(mean_prec)
    st.policy = PolicyParams(**{**policy.__dict__, "cov": 0.5 * (cov + cov.T)})


def seed_policy_cov(controllers: list[LinearGaussian], Xs: np.ndarray,
                    policy: PolicyParams) -> np.ndarray:
    """The state-independent Sigma_pi minimising sum_t E_p(x) KL(p || pi) (eq. 5.5 as printed):
    the mean over conditions, steps and samples of C_t + (mu_p - mu_pi)(mu_p - mu_pi)'."""
    covs = []
    for ctrl, X in zip(controllers, Xs, strict=True):
        d = np.einsum("tux,mtx->mtu", ctrl.K, X) + ctrl.k - policy.mean(X)
        m, horizon = d.shape[:2]
        covs.append(ctrl.cov.mean(axis=0) + np.einsum("mti,mtj->ij", d, d) / (m * horizon))
    return np.mean(covs, axis=0)


def dual_step(lam: np.ndarray, nu: np.ndarray, mu_pi: np.ndarray, mu_p: np.ndarray,
              pol_cov: np.ndarray, rate: float) -> np.ndarray:
    """Eq. 5.7 for one condition: lambda_t + alpha nu_t Sigma_pi^-1 (E[pi u] - E[p u]), the
    expectations over the sample states (mu_pi, mu_p: (M, T, dU) mean actions there).

    The difference is in N m and N while lambda is in cost per action unit: we take alpha's units
    from the policy's action precision (Sigma_pi^-1, our departure from the literal eq. 5.7),
    which makes the shift lambda induces in eq. 5.5's target alpha times the difference instead
    of overshooting."""
    gap = (mu_pi - mu_p).mean(axis=0) @ np.linalg.inv(pol_cov).T
    return lam + rate * nu[:, None] * gap


def adapt_nu(nu: np.ndarray, kl_t: np.ndarray, target: float, lo: float,
             hi: float) -> np.ndarray:
    """nu_t doubles where E KL(p || pi) exceeds ``target``, halves where it is below a quarter of
    it, and stays within [lo, hi]."""
    nu = np.where(kl_t > target, nu * 2.0, np.where(kl_t < target / 4, nu / 2.0, nu))
    return np.clip(nu, lo, hi)


def inner_loop(cfg: GPSFileConfig, st: GPSState, Xs: np.ndarray, dyns: list[LinearDynamics],
               expansions: list[tuple[np.ndarray, np.ndarray]],
               iteration: int) -> tuple[list[float], list[float]]:
    """BADMM's alternation on one iteration's samples Xs (C, M, T, dX), ``inner_iterations``
    times: policy step (eq. 5.5), dual step (eq. 5.7), nu adaptation, LQG step (eq. 5.6) from the
    controllers that produced the samples. Updates ``st``; returns the last pass's eta and mean
    KL(p || pi) per condition."""
    g = cfg.gps
    seed_kl = g.kl_directions == "seed"
    sampled = list(st.controllers)
    etas: list[float] = []
    kls: list[float] = []
    for inner in range(g.inner_iterations):
        _update_policy(cfg, st, Xs, g.seed + 1000 * iteration + inner)
        new_ctrls = []
        kls = []
        etas = []
        for i, (dyn, (Cm, cv)) in enumerate(zip(dyns, expansions, strict=True)):
            X = Xs[i]
            lin = _policy_linearization(st.policy, X)
            ctrl = st.controllers[i]
            mu_pi = st.policy.mean(X)
            mu_p = np.einsum("tux,mtx->mtu", ctrl.K, X) + ctrl.k
            st.lam[i] = dual_step(st.lam[i], st.nu[i], mu_pi, mu_p, st.policy.cov, g.dual_rate)
            # nu_t grows where the local controller and the policy disagree, shrinks where not,
            # measured by the KL the trajectory step penalises.
            mu_x, sig_x = _sample_moments(X)
            kl_t = (kl_per_step(mu_x, sig_x, lin, ctrl) if seed_kl
                    else kl_per_step(mu_x, sig_x, ctrl, lin))
            st.nu[i] = adapt_nu(st.nu[i], kl_t, g.kl_policy_target, g.nu_init, g.nu_max)
            new, eta, _ = lqg_update(dyn, Cm, cv, sampled[i], lin, st.nu[i], st.lam[i], g.kl_step,
                                     seed_directions=seed_kl)
            new_ctrls.append(new)
            etas.append(eta)
            kls.append(float(kl_t.mean()))
        st.controllers = new_ctrls
    return etas, kls


def initial_state(cfg: GPSFileConfig, scene: HandoverScene, motions: list[TesterMotion],
                  kind: StateKind) -> GPSState:
    g = cfg.gps
    horizon, dx = cfg.scene.horizon, DIMS[kind]
    lo, hi = scene.u_bounds
    ctrls = []
    for mo in motions:
        x0 = state_vector(scene.reset(mo), kind)
        ctrls.append(pd_controller(x0, np.array(g.init_kp), np.array(g.init_kd), horizon, dx, DU,
                                   g.init_std_frac * hi))
    policy = init_policy(dx, DU, g.hidden_units, hi, g.seed)
    n = len(motions)
    return GPSState(ctrls, np.zeros((n, horizon, DU)), np.full((n, horizon), g.nu_init), policy)


def iterate(cfg: GPSFileConfig, scene: HandoverScene, motions: list[TesterMotion],
            kind: StateKind, st: GPSState, prior: GMMPrior, buffer: list[np.ndarray],
            rng: np.random.Generator, iteration: int) -> IterationLog:
    """One BADMM GPS iteration (updates ``st``, ``prior`` and ``buffer`` in place)."""
    g = cfg.gps
    cost = cost_for(cfg, kind)
    trials: list[list[Trial]] = []
    for mo, ctrl in zip(motions, st.controllers, strict=True):
        def act(t: int, x: np.ndarray, c: LinearGaussian = ctrl) -> np.ndarray:
            return c.act(t, x, rng.standard_normal(DU))
        trials.append([run_trial(scene, mo, kind, act) for _ in range(g.samples)])
    Xs = np.array([[tr.X for tr in ts] for ts in trials])  # (C, M, T, dX)
    Us = np.array([[tr.U for tr in ts] for ts in trials])
    local_cost = float(np.mean(cost.total(Xs, Us).sum(axis=-1)))
    local_err = float(np.mean([tr.final_error() for ts in trials for tr in ts]))

    buffer.append(np.concatenate([transitions(X, U) for X, U in zip(Xs, Us, strict=True)]))
    del buffer[:-g.prior_iterations]
    prior.fit(np.concatenate(buffer))
    dyns = [fit_dynamics(X, U, prior, g.prior_strength) for X, U in zip(Xs, Us, strict=True)]
    expansions = [cost.expand(X, U) for X, U in zip(Xs, Us, strict=True)]
    etas, kls = inner_loop(cfg, st, Xs, dyns, expansions, iteration)
    pol_err = float(np.mean([run_trial(scene, mo, kind, policy_act(st.policy)).final_error()
                             for mo in motions]))
    entry = IterationLog(iteration, local_cost, local_err, pol_err, float(np.mean(kls)),
                         float(st.nu.mean()), float(np.mean(etas)))
    st.log.append(entry)
    return entry


def _run(cfg: GPSFileConfig, targets: np.ndarray, moving: bool, kind: StateKind,
         st: GPSState | None, buffer: list[np.ndarray], rng: np.random.Generator,
         n_iter: int, progress: bool) -> TrainResult:
    """``n_iter`` iterations on ``targets`` from ``st`` (None: fresh PD controllers and policy),
    numbered after the iterations already in its log."""
    from tqdm import tqdm

    motions = [motion_to(p, moving, cfg.scene.tester) for p in targets]
    scene = HandoverScene(cfg.scene)
    prior = GMMPrior(cfg.gps.gmm_clusters, cfg.gps.seed)
    with threadpool_limits(1):  # the machine is shared; BLAS threads only oversubscribe it
        if st is None:
            st = initial_state(cfg, scene, motions, kind)
        done = len(st.log)
        bar = tqdm(range(done, done + n_iter), desc="GPS", unit="it", disable=not progress)
        for it in bar:
            e = iterate(cfg, scene, motions, kind, st, prior, buffer, rng, it)
            bar.set_postfix(local_mm=f"{1e3 * e.local_error_m:.0f}",
                            policy_mm=f"{1e3 * e.policy_error_m:.0f}", kl=f"{e.policy_kl:.2f}")
        errs = np.array([run_trial(scene, mo, kind, policy_act(st.policy)).final_error()
                         for mo in motions])
    return TrainResult(st.policy, st, kind, np.asarray(targets), moving, errs, buffer,
                       dict(rng.bit_generator.state))


def train(cfg: GPSFileConfig, controllers: int, moving: bool, kind: StateKind,
          iterations: int | None = None, targets: np.ndarray | None = None,
          progress: bool = False) -> TrainResult:
    """Train a global policy with ``controllers`` local controllers (8 or 12 shell targets unless
    ``targets`` are given) against a static or moving trainer."""
    tg = training_targets(cfg.shell, controllers) if targets is None else np.asarray(targets)
    rng = np.random.default_rng(cfg.gps.seed)
    n_iter = cfg.gps.iterations if iterations is None else iterations
    return _run(cfg, tg, moving, kind, None, [], rng, n_iter, progress)


def continue_training(cfg: GPSFileConfig, previous: TrainResult, new_targets: np.ndarray,
                      iterations: int | None = None, progress: bool = False) -> TrainResult:
    """The seed's 12-controller run, "adding four additional local controllers" to a trained
    run: ``previous``'s local controllers, their multipliers and KL weights, the global policy,
    the prior's transition buffer and the generator's state are kept; one fresh local
    controller (the initial PD law, lambda 0, nu_init) is added per ``new_targets`` row; then
    ``iterations`` (default: the config's) more iterations train all of them."""
    new_targets = np.atleast_2d(np.asarray(new_targets, float))
    old = previous.state
    scene = HandoverScene(cfg.scene)
    motions = [motion_to(p, previous.moving, cfg.scene.tester) for p in new_targets]
    fresh = initial_state(cfg, scene, motions, previous.kind)
    st = GPSState(
        controllers=[*old.controllers, *fresh.controllers],
        lam=np.concatenate([old.lam, fresh.lam]),
        nu=np.concatenate([old.nu, fresh.nu]),
        policy=old.policy,
        log=list(old.log),
    )
    rng = np.random.default_rng(cfg.gps.seed)
    if previous.rng_state is not None:
        rng.bit_generator.state = previous.rng_state  # the sampling continues where it stopped
    targets = np.concatenate([previous.targets, new_targets])
    n_iter = cfg.gps.iterations if iterations is None else iterations
    return _run(cfg, targets, previous.moving, previous.kind, st, list(previous.buffer), rng,
                n_iter, progress)
