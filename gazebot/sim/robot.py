"""What the simulation needs to know about a robot: its MJCF, which joints are head and arm, and the
arm's home and predefined handover poses. Read from the robot YAML (``configs/robots/<name>.yaml``,
written by the kinematics package) so the simulation and the gaze engine share one description."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gazebot.config import ConfigError, configs_dir, read_yaml

ASSETS = Path(__file__).resolve().parents[1] / "assets" / "robots"


@dataclass(frozen=True)
class SimRobot:
    """A robot as the simulation uses it (angles in rad)."""

    name: str
    mjcf: Path
    head_joints: tuple[str, ...]
    arm_joints: tuple[str, ...]
    home: np.ndarray  # arm joints at home
    handover: np.ndarray  # arm joints at the predefined handover pose
    gripper_actuator: str = "gripper"
    gripper_site: str = "gripper"
    gaze_site: str = "gaze"


def _pose(data: dict[str, Any], key: str, joints: tuple[str, ...], source: Path) -> np.ndarray:
    """A pose given in degrees as a mapping joint -> deg or a list in ``arm_joints`` order."""
    raw = data.get(key)
    if isinstance(raw, dict):
        missing = [j for j in joints if j not in raw]
        if missing:
            raise ConfigError(source, key, f"a value for every arm joint (missing {missing})")
        values = [raw[j] for j in joints]
    elif isinstance(raw, list) and len(raw) == len(joints):
        values = raw
    else:
        raise ConfigError(source, key, f"{len(joints)} arm joint angles in degrees", raw)
    try:
        out = np.deg2rad(np.asarray(values, dtype=float))
    except (TypeError, ValueError) as exc:
        raise ConfigError(source, key, "numbers (degrees)", raw) from exc
    if not np.all(np.isfinite(out)):
        raise ConfigError(source, key, "finite numbers (degrees)", raw)
    return out


def load_sim_robot(robot: str | Path) -> SimRobot:
    """Load ``configs/robots/<robot>.yaml`` (or a YAML path) as a :class:`SimRobot`.

    Raises:
        FileNotFoundError: no such robot.
        ConfigError: a field the simulation needs is missing or malformed.
    """
    path = Path(robot)
    if path.suffix not in (".yaml", ".yml"):
        path = configs_dir() / "robots" / f"{robot}.yaml"
    if not path.is_file():
        known = sorted(p.stem for p in (configs_dir() / "robots").glob("*.yaml"))
        raise FileNotFoundError(f"unknown robot {str(robot)!r}: no file {path} (known: {known})")
    data = read_yaml(path)
    if not isinstance(data, dict):
        raise ConfigError(path, "<root>", "a mapping")
    mjcf_raw = data.get("mjcf")
    if not isinstance(mjcf_raw, str):
        raise ConfigError(path, "mjcf", "the robot's MJCF file name", mjcf_raw)
    mjcf = Path(mjcf_raw)
    if not mjcf.is_absolute():
        candidates = [path.parent / mjcf, ASSETS / mjcf, ASSETS / mjcf.name]
        mjcf = next((c for c in candidates if c.is_file()), candidates[-1])
    if not mjcf.is_file():
        raise ConfigError(path, "mjcf", f"an existing MJCF file (looked for {mjcf})", mjcf_raw)
    joints: dict[str, tuple[str, ...]] = {}
    for key in ("head_joints", "arm_joints"):
        raw = data.get(key)
        if not (isinstance(raw, list) and raw and all(isinstance(j, str) for j in raw)):
            raise ConfigError(path, key, "a non-empty list of joint names", raw)
        joints[key] = tuple(raw)
    arm = joints["arm_joints"]
    names = {}
    for key in ("gripper_actuator", "gripper_site", "gaze_site"):
        raw = data.get(key, key.split("_")[0])
        if not isinstance(raw, str) or not raw:
            raise ConfigError(path, key, "a name in the MJCF", raw)
        names[key] = raw
    return SimRobot(
        name=str(data.get("name", path.stem)),
        mjcf=mjcf,
        head_joints=joints["head_joints"],
        arm_joints=arm,
        home=_pose(data, "arm_home_deg", arm, path),
        handover=_pose(data, "arm_handover_deg", arm, path),
        **names,
    )
