"""A trained policy on disk: ``DIR/policy.npz`` (network) and ``DIR/meta.json`` (how it was
trained: state kind, trainer, targets, the configuration, the iteration log)."""

from __future__ import annotations

import json
import zipfile
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from gazebot.apps.gps.badmm import TrainResult
from gazebot.apps.gps.config import GPSFileConfig
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
    }
    (out / "meta.json").write_text(json.dumps(meta, indent=2) + "\n", encoding="utf-8")


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
