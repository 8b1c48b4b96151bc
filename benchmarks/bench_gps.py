"""The seed's chapter-5 GPS: training and evaluation wall time (opt-in: set GAZEBOT_BENCH_GPS=1;
a training of 8 controllers x 12 iterations and the full 2299-location evaluation take minutes).

Budgets (issue 22): training <= 20 min, evaluation <= 10 min on the 2-core machine. Peers measured
in the same run: the policy's action in the rollout loop through a jitted JAX call (what training
uses) against our numpy forward pass; the GMM prior's fit (sklearn, k-means++ start, at most 10 EM
steps, tol 1e-3) against sklearn's default k-means start doing the same EM work (the same
max_iter and tol; each fit's EM step count is printed) on the same 4680 transitions of the scene
(3 iterations' worth: the trained policy with its action noise, 5 trials per training target,
three times), which is what ``configs/gps.yaml``'s prior_iterations = 3 fits during training.
"""

from __future__ import annotations

import os
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from benchmarks.common import Result, median_time


def _enabled() -> bool:
    return os.environ.get("GAZEBOT_BENCH_GPS") == "1"


def run() -> list[Result]:
    if not _enabled():
        return [Result("gps (opt-in: GAZEBOT_BENCH_GPS=1)", float("nan"), None, "s",
                       note="skipped: takes minutes")]
    import jax

    from gazebot.apps.gps.badmm import train
    from gazebot.apps.gps.config import load_gps_config
    from gazebot.apps.gps.evaluate import evaluate
    from gazebot.apps.gps.policy_store import load, save
    from gazebot.apps.gps.state import StateKind

    cfg = load_gps_config()
    out: list[Result] = []
    t0 = time.perf_counter()
    result = train(cfg, 8, False, StateKind.REDUCED)
    train_s = time.perf_counter() - t0
    train_mm = 1e3 * result.train_errors_m.mean()
    out.append(Result("train 8 controllers x 12 iterations", train_s, None, "s",
                      note=f"budget 1200 s; train error {train_mm:.0f} mm"))
    with tempfile.TemporaryDirectory() as tmp:
        save(result, cfg, Path(tmp), train_s)
        trained = load(tmp)
        t0 = time.perf_counter()
        ev = evaluate(trained, moving=False)
        eval_s = time.perf_counter() - t0
    out.append(Result(f"evaluate {ev.errors.size} static locations", eval_s, None, "s",
                      note=f"budget 600 s; mean error {1e3 * ev.errors.mean():.0f} mm"))

    policy = result.policy
    x = np.zeros(policy.x_mean.shape)
    params = {k: getattr(policy, k) for k in ("w1", "b1", "w2", "b2", "x_mean", "x_scale",
                                              "u_scale")}

    @jax.jit
    def jax_mean(p, xx):
        h = jax.nn.relu(((xx - p["x_mean"]) / p["x_scale"]) @ p["w1"] + p["b1"])
        return (h @ p["w2"] + p["b2"]) * p["u_scale"]

    def jax_act():
        return np.asarray(jax_mean(params, x))

    ours = median_time(lambda: policy.mean(x), repeat=7, number=2000)
    peer = median_time(jax_act, repeat=7, number=2000)
    out.append(Result("policy action per control step", ours * 1e6, peer * 1e6, "us",
                      peer_name="jax.jit call"))

    out.append(gmm_result(trained, cfg.gps.gmm_clusters))
    return out


def scene_transitions(trained, repeats: int = 3, samples: int = 5, seed: int = 0) -> np.ndarray:
    """Transitions (x_t, u_t, x_t+1) of the trained policy with its Gaussian action noise on each
    training target: ``repeats`` x ``samples`` trials per target, as the prior sees in training."""
    from gazebot.apps.gps.dynamics import transitions
    from gazebot.apps.gps.reach_scene import HandoverScene
    from gazebot.apps.gps.tester import motion_to
    from gazebot.apps.gps.trial import run_trial

    rng = np.random.default_rng(seed)
    scene = HandoverScene(trained.cfg.scene)
    chol = np.linalg.cholesky(trained.policy.cov)
    rows = []
    for p in trained.targets:
        mo = motion_to(p, trained.moving, trained.cfg.scene.tester)
        for _ in range(repeats * samples):
            tr = run_trial(scene, mo, trained.kind, lambda t, x: trained.policy.mean(x)
                           + chol @ rng.standard_normal(chol.shape[0]))
            rows.append(transitions(tr.X[None], tr.U[None]))
    return np.concatenate(rows)


def gmm_result(trained, clusters: int) -> Result:
    """Our GMM prior fit against sklearn's default k-means initialisation with the same EM budget
    (max_iter and tol) on the same scene transitions."""
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.mixture import GaussianMixture

    from gazebot.apps.gps.dynamics import GMMPrior

    pts = scene_transitions(trained)
    prior = GMMPrior(clusters)
    ours = median_time(lambda: prior.fit(pts), repeat=3, warmup=0)
    assert prior.gmm is not None
    budget = {"max_iter": prior.gmm.max_iter, "tol": prior.gmm.tol}
    peer_gmm = GaussianMixture(clusters, covariance_type="full", reg_covar=1e-6,
                               random_state=0, **budget)

    def peer_fit() -> None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            peer_gmm.fit(pts)

    peer = median_time(peer_fit, repeat=3, warmup=0)
    return Result(f"GMM prior fit ({pts.shape[0]} transitions of {pts.shape[1]})", ours, peer,
                  "s", peer_name=f"sklearn k-means start, max_iter {budget['max_iter']}, "
                  f"tol {budget['tol']:g}",
                  note=f"EM steps: ours {prior.gmm.n_iter_}, peer {peer_gmm.n_iter_}; "
                  f"mean log-likelihood ours {prior.gmm.score(pts):.1f}, "
                  f"peer {peer_gmm.score(pts):.1f}")
