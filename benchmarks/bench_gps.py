"""The seed's chapter-5 GPS: training and evaluation wall time (opt-in: set GAZEBOT_BENCH_GPS=1;
a training of 8 controllers x 12 iterations and the full 2299-location evaluation take minutes).

Budgets (issue 22): training <= 20 min, evaluation <= 10 min on the 2-core machine. Peers measured
in the same run: the policy's action in the rollout loop through a jitted JAX call (what training
uses) against our numpy forward pass; the GMM prior's fit with sklearn's defaults (k-means start,
up to 100 EM steps) against ours (k-means++ start, 10 EM steps) on the same transitions.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.common import Result, median_time


def _enabled() -> bool:
    return os.environ.get("GAZEBOT_BENCH_GPS") == "1"


def run() -> list[Result]:
    if not _enabled():
        return [Result("gps (opt-in: GAZEBOT_BENCH_GPS=1)", float("nan"), None, "s",
                       note="skipped: takes tens of minutes")]
    import jax
    from sklearn.mixture import GaussianMixture

    from gazebot.gps.badmm import train
    from gazebot.gps.config import load_gps_config
    from gazebot.gps.dynamics import GMMPrior
    from gazebot.gps.evaluate import evaluate
    from gazebot.gps.state import StateKind
    from gazebot.gps.store import load, save

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

    rng = np.random.default_rng(0)
    pts = rng.standard_normal((4680, 2 * policy.x_mean.size + 8))
    prior = GMMPrior(cfg.gps.gmm_clusters)
    ours = median_time(lambda: prior.fit(pts), repeat=3, warmup=0)
    peer = median_time(lambda: GaussianMixture(cfg.gps.gmm_clusters, covariance_type="full",
                                               reg_covar=1e-6, random_state=0).fit(pts),
                       repeat=3, warmup=0)
    out.append(Result("GMM prior fit (4680 transitions)", ours, peer, "s",
                      peer_name="sklearn defaults"))
    return out
