"""A trained policy on disk: ``DIR/policy.npz`` (network), ``DIR/meta.json`` (how it was
trained: state kind, trainer, targets, the configuration, the iteration log, the sampling
generator's state) and ``DIR/state.npz`` (what continuing the run needs: the local controllers,
their Lagrange multipliers and KL weights, the dynamics prior's transition buffer;
``gazebot gps train --add-controllers N --from DIR``)."""

from __future__ import annotations

import json
import zipfile
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from gazebot.apps.gps.badmm import GPSState, IterationLog, TrainResult
from gazebot.apps.gps.config import GPSFileConfig
from gazebot.apps.gps.lingauss import LinearGaussian
from gazebot.apps.gps.policy import PolicyParams
from gazebot.apps.gps.reach_scene import DU
from gazebot.apps.gps.state import DIMS, StateKind
from gazebot.core.config import ConfigError, validate


@dataclass(frozen=True)
class TrainedPolicy:
    policy: PolicyParams
    cfg: GPSFileConfig
    kind: StateKind
    moving: bool
    targets: np.ndarray
    controllers: int
    log: list[dict]


def save(result: TrainResult, cfg: GPSFileConfig, out: Path, seconds: float) -> None:
    out.mkdir(parents=True, exist_ok=True)
    result.policy.save(out / "policy.npz")
    meta = {
        "controllers": len(result.targets),
        "trainer": "moving" if result.moving else "static",
        "state": result.kind.value,
        "targets_m": result.targets.tolist(),
        "train_errors_m": result.train_errors_m.tolist(),
        "train_seconds": seconds,
        "log": [asdict(e) for e in result.state.log],
        "config": cfg.model_dump(mode="json"),
        "rng_state": result.rng_state,
    }
    st = result.state
    arrays: dict[str, np.ndarray] = {
        "K": np.array([c.K for c in st.controllers]),
        "k": np.array([c.k for c in st.controllers]),
        "cov": np.array([c.cov for c in st.controllers]),
        "lam": st.lam,
        "nu": st.nu,
        **{f"buffer_{i}": b for i, b in enumerate(result.buffer)},
    }
    np.savez(out / STATE_FILE, **arrays)  # type: ignore[arg-type]
    (out / "meta.json").write_text(json.dumps(meta, indent=2) + "\n", encoding="utf-8")


STATE_FILE = "state.npz"


def load(directory: str | Path) -> TrainedPolicy:
    """Load a policy directory written by ``gazebot gps train``."""
    d = Path(directory)
    meta_path = d / "meta.json"
    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
    except FileNotFoundError as exc:
        raise ConfigError(meta_path, "<file>", "a policy directory from `gazebot gps train`",
                          "no meta.json") from exc
    except json.JSONDecodeError as exc:
        raise ConfigError(meta_path, "<file>", "JSON", str(exc)) from exc
    for key in ("controllers", "trainer", "state", "targets_m", "config"):
        if key not in meta:
            raise ConfigError(meta_path, key, "a value (the field is required)")
    if meta["trainer"] not in ("static", "moving"):
        raise ConfigError(meta_path, "trainer", "static or moving", meta["trainer"])
    try:
        kind = StateKind(meta["state"])
    except ValueError as exc:
        raise ConfigError(meta_path, "state", "full, reduced or relative", meta["state"]) from exc
    cfg = validate(GPSFileConfig, meta["config"], f"{meta_path}:config")
    try:
        policy = PolicyParams.load(d / "policy.npz")
    except (OSError, KeyError, ValueError, zipfile.BadZipFile) as exc:
        raise ConfigError(d / "policy.npz", "<file>", "the policy network's arrays",
                          str(exc)) from exc
    problem = policy.shape_error(DIMS[kind], DU)
    if problem is not None:
        name, expected, got = problem
        raise ConfigError(d / "policy.npz", name,
                          f"{expected} for the {kind.value} state in meta.json "
                          f"({DIMS[kind]} values) and {DU} actions", got)
    return TrainedPolicy(policy, cfg, kind, meta["trainer"] == "moving",
                         np.asarray(meta["targets_m"], dtype=float), int(meta["controllers"]),
                         list(meta.get("log", [])))


def load_checkpoint(directory: str | Path) -> tuple[TrainResult, GPSFileConfig]:
    """A trained run as :func:`gazebot.apps.gps.badmm.continue_training` takes it, and the
    configuration it was trained with.

    Raises:
        ConfigError: not a run directory, a run saved without ``state.npz`` (trained before
            runs could be continued), or arrays that do not fit its controllers and state.
    """
    trained = load(directory)
    d = Path(directory)
    path = d / STATE_FILE
    if not path.is_file():
        raise ConfigError(path, "<file>", "the run's BADMM state (written by `gazebot gps "
                          "train` since --add-controllers exists)", "no state.npz: retrain it")
    meta = json.loads((d / "meta.json").read_text(encoding="utf-8"))
    try:
        with np.load(path) as z:
            arrays = {name: z[name] for name in z.files}
    except (OSError, ValueError, zipfile.BadZipFile) as exc:
        raise ConfigError(path, "<file>", "the run's BADMM state arrays", str(exc)) from exc
    c, horizon, dx = trained.controllers, trained.cfg.scene.horizon, DIMS[trained.kind]
    shapes = {"K": (c, horizon, DU, dx), "k": (c, horizon, DU), "cov": (c, horizon, DU, DU),
              "lam": (c, horizon, DU), "nu": (c, horizon)}
    for name, shape in shapes.items():
        got = arrays.get(name)
        if got is None or got.shape != shape or not np.all(np.isfinite(got)):
            raise ConfigError(path, name, f"finite values of shape {shape}",
                              "missing" if got is None else got.shape)
    buffer = [arrays[f"buffer_{i}"] for i in range(len(arrays)) if f"buffer_{i}" in arrays]
    controllers = [LinearGaussian(K, k, cov)
                   for K, k, cov in zip(arrays["K"], arrays["k"], arrays["cov"], strict=True)]
    log = [IterationLog(**e) for e in trained.log]
    state = GPSState(controllers, arrays["lam"], arrays["nu"], trained.policy, log)
    result = TrainResult(trained.policy, state, trained.kind, trained.targets, trained.moving,
                         np.asarray(meta.get("train_errors_m", []), float), buffer,
                         meta.get("rng_state"))
    return result, trained.cfg
