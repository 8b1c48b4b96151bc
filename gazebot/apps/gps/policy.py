"""The global policy pi_theta(u | x): a neural network with one hidden layer of 84 ReLU units (seed
5.4) and a Gaussian action noise, trained by supervised learning on the local controllers'
samples (eq. 5.5) with JAX and optax (the optional ``gps`` extra).

The network's loss on sample (x, t) of condition i (built in ``badmm._update_policy``) is
nu_t 1/2 (mu(x) - mu_i(x))' P (mu(x) - mu_i(x)) + mu(x)' lambda_t, with P = C_t^-1 the local
controller's action precision: the Lagrange term of eq. 5.5 plus the mean part of
nu_t KL(pi || p_i), NOT of the seed's KL(p_i || pi) (whose mean part would be weighted by the
policy's precision). Its covariance is the inverse of the local controllers' mean precision, the
minimiser of the covariance part of that same KL(pi || p_i). This is the direction of Levine et
al.'s BADMM (the seed's reference [92]); the README's "where we differ" says why. With
``kl_directions: seed`` the weights are the policy's own precision and the covariance
``badmm.seed_policy_cov`` (eq. 5.5 as printed).
"""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np


def _jax():
    try:
        import jax
        import jax.numpy as jnp
        import optax
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "the GPS global policy needs JAX and optax: pip install 'gazebot[gps]'"
        ) from exc
    return jax, jnp, optax


@dataclass(frozen=True)
class PolicyParams:
    """Weights of the network, input normalisation and output scale, and the action covariance."""

    w1: np.ndarray  # (dX, H)
    b1: np.ndarray  # (H,)
    w2: np.ndarray  # (H, dU)
    b2: np.ndarray  # (dU,)
    x_mean: np.ndarray  # (dX,)
    x_scale: np.ndarray  # (dX,)
    u_scale: np.ndarray  # (dU,)
    cov: np.ndarray  # (dU, dU)

    def mean(self, x: np.ndarray) -> np.ndarray:
        """The policy's mean action for states x (..., dX), in numpy (fast for rollouts)."""
        h = np.maximum(((x - self.x_mean) / self.x_scale) @ self.w1 + self.b1, 0.0)
        return (h @ self.w2 + self.b2) * self.u_scale

    def save(self, path: Path) -> None:
        np.savez(path, **{k: getattr(self, k) for k in self.__dataclass_fields__})

    @classmethod
    def load(cls, path: Path) -> PolicyParams:
        with np.load(path) as z:
            return cls(**{k: z[k] for k in cls.__dataclass_fields__})

    def shape_error(self, dx: int, du: int) -> tuple[str, str, str] | None:
        """(array, what was expected, what it is) for the first array that does not fit states
        of size ``dx`` and actions of size ``du``, else ``None``: a network saved for another
        state representation would otherwise fail deep inside a rollout."""
        hidden = self.b1.shape[0] if self.b1.ndim == 1 and self.b1.shape[0] > 0 else None
        expected = {
            "b1": (hidden or "H",), "w1": (dx, hidden), "w2": (hidden, du), "b2": (du,),
            "x_mean": (dx,), "x_scale": (dx,), "u_scale": (du,), "cov": (du, du),
        }
        for name, shape in expected.items():
            value = getattr(self, name)
            if hidden is None or value.shape != shape:
                return name, f"shape {shape}", str(value.shape)
            if not np.issubdtype(value.dtype, np.floating) or not np.all(np.isfinite(value)):
                return name, "finite floats", f"{value.dtype} with non-finite values"
        return None


def init_policy(dx: int, du: int, hidden: int, u_scale: np.ndarray, seed: int) -> PolicyParams:
    """He-initialised weights, zero biases, identity normalisation."""
    rng = np.random.default_rng(seed)
    return PolicyParams(
        w1=rng.standard_normal((dx, hidden)) * np.sqrt(2.0 / dx),
        b1=np.zeros(hidden),
        w2=rng.standard_normal((hidden, du)) * np.sqrt(1.0 / hidden) * 0.1,
        b2=np.zeros(du),
        x_mean=np.zeros(dx),
        x_scale=np.ones(dx),
        u_scale=np.asarray(u_scale, dtype=float),
        cov=np.eye(du),
    )


def input_scale(std: np.ndarray) -> np.ndarray:
    """Per-feature input scale from the training spread. A feature constant in training (the
    hand's velocity under a static trainer) gets 1 SI unit: its weights never learn, and dividing
    by a tiny floor would amplify an unseen value (a moving tester's hand) a thousandfold."""
    return np.where(std < 1e-9, 1.0, np.maximum(std, 1e-3))


@functools.lru_cache(maxsize=8)
def _fitter(batch: int, learning_rate: float):
    """The jitted Adam loop; compiled once per data shape, not once per call."""
    jax, jnp, optax = _jax()
    opt = optax.adam(learning_rate)

    def loss(th, xb, tb, wb):
        h = jax.nn.relu(xb @ th["w1"] + th["b1"])
        diff = h @ th["w2"] + th["b2"] - tb
        return 0.5 * jnp.mean(jnp.einsum("bi,bij,bj->b", diff, wb, diff))

    def run(theta, xn, tg, wt, keys):
        n = xn.shape[0]
        b = min(batch, n)

        def step(carry, key):
            th, state = carry
            idx = jax.random.randint(key, (b,), 0, n)
            g = jax.grad(loss)(th, xn[idx], tg[idx], wt[idx])
            upd, state = opt.update(g, state, th)
            return (optax.apply_updates(th, upd), state), None

        (theta, _), _ = jax.lax.scan(step, (theta, opt.init(theta)), keys)
        return theta

    return jax.jit(run)


def train_policy(params: PolicyParams, X: np.ndarray, targets: np.ndarray, weights: np.ndarray,
                 steps: int, batch: int, learning_rate: float, seed: int) -> PolicyParams:
    """Fit the network to ``targets`` (N, dU) at states ``X`` (N, dX) under the weighted Euclidean
    loss 1/2 (mu(x) - target)' W (mu(x) - target), W = ``weights`` (N, dU, dU), by Adam.

    The input normalisation is refitted to X; the weights continue from ``params``.
    """
    jax, jnp, _ = _jax()
    x_mean = X.mean(axis=0)
    x_scale = input_scale(X.std(axis=0))
    xn = jnp.asarray((X - x_mean) / x_scale, dtype=jnp.float32)
    us = params.u_scale
    tg = jnp.asarray(targets / us, dtype=jnp.float32)
    # W acts on actions; in scaled units it is diag(us) W diag(us).
    wt = jnp.asarray(weights * us[None, :, None] * us[None, None, :], dtype=jnp.float32)
    theta = {k: jnp.asarray(getattr(params, k), dtype=jnp.float32)
             for k in ("w1", "b1", "w2", "b2")}
    keys = jax.random.split(jax.random.PRNGKey(seed), steps)
    theta = _fitter(batch, learning_rate)(theta, xn, tg, wt, keys)
    out = {k: np.asarray(v, dtype=float) for k, v in theta.items()}
    return PolicyParams(**out, x_mean=x_mean, x_scale=x_scale, u_scale=us, cov=params.cov)


def jacobians(params: PolicyParams, X: np.ndarray) -> np.ndarray:
    """d mu / d x at each state of X (N, dX): (N, dU, dX), exact for the ReLU network."""
    z = ((X - params.x_mean) / params.x_scale) @ params.w1 + params.b1
    active = (z > 0).astype(float)  # (N, H)
    # mu = us * (relu(((x - m) / s) W1 + b1) W2 + b2)
    inner = params.w1.T[None] * active[..., None] / params.x_scale[None, None, :]  # (N, H, dX)
    return params.u_scale[None, :, None] * np.einsum("hu,nhx->nux", params.w2, inner)


def save_meta(path: Path, meta: dict) -> None:
    path.write_text(json.dumps(meta, indent=2) + "\n", encoding="utf-8")
