"""What the simulation needs to know about a robot: its MJCF, which joints are head and arm, and the
arm's home and predefined handover poses.

The robot YAML (``configs/robots/<name>.yaml``) has one parser, the kinematics package's pydantic
:class:`~gazebot.core.kinematics.RobotConfig`; this module only converts the parsed config to
what the simulation uses (radians, joint order, the resolved MJCF path), so the simulation, the
gaze engine and the eye renderer all read the same description.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gazebot.core.config import ConfigError
from gazebot.core.kinematics.robot_config import RobotConfig, load_robot_config, resolve_mjcf


@dataclass(frozen=True)
class SimRobot:
    """A robot as the simulation uses it (angles in rad), with the config it came from."""

    name: str
    mjcf: Path
    head_joints: tuple[str, ...]
    arm_joints: tuple[str, ...]
    home: np.ndarray  # arm joints at home
    handover: np.ndarray  # arm joints at the predefined handover pose
    config: RobotConfig
    source: Path | None = None  # the robot YAML, None for a config built in code
    gripper_actuator: str = "gripper"
    gripper_site: str = "gripper"
    gaze_site: str = "gaze"

    @property
    def spec(self) -> str | Path | RobotConfig:
        """What to hand to other loaders (gaze engine, eye renderer) for the same robot: the
        YAML path when there is one (a relative ``mjcf`` resolves beside it), else the config."""
        return self.source if self.source is not None else self.config


def _pose_rad(config: RobotConfig, key: str, source: Path | str) -> np.ndarray:
    """``arm_home_deg`` / ``arm_handover_deg`` (validated: exactly the arm joints) in rad, in
    ``arm_joints`` order."""
    pose = getattr(config, key)
    out = np.deg2rad(np.array([pose[j] for j in config.arm_joints], dtype=float))
    if not np.all(np.isfinite(out)):
        raise ConfigError(source, key, "finite joint angles (degrees)", pose)
    return out


def sim_robot_from_config(config: RobotConfig, source: Path | None = None) -> SimRobot:
    """The simulation's view of a parsed robot config (``source``: its YAML, for a relative MJCF).

    Raises:
        ConfigError: the MJCF file does not exist or a pose is not finite.
    """
    where: Path | str = source if source is not None else f"<robot config {config.name!r}>"
    return SimRobot(
        name=config.name,
        mjcf=resolve_mjcf(config, source),
        head_joints=tuple(config.head_joints),
        arm_joints=tuple(config.arm_joints),
        home=_pose_rad(config, "arm_home_deg", where),
        handover=_pose_rad(config, "arm_handover_deg", where),
        config=config,
        source=source,
        gripper_actuator=config.gripper_actuator,
        gripper_site=config.gripper_site,
        gaze_site=config.gaze_site,
    )


def load_sim_robot(robot: str | Path | RobotConfig) -> SimRobot:
    """A robot by name (``configs/robots/<robot>.yaml``), YAML path or parsed :class:`RobotConfig`.

    Raises:
        FileNotFoundError: no such robot.
        ConfigError: the YAML is malformed (names file, field and expectation).
    """
    if isinstance(robot, RobotConfig):
        return sim_robot_from_config(robot)
    config, path = load_robot_config(robot)
    return sim_robot_from_config(config, path)
