"""Which screen a robot's eyes are drawn on: resolution, eye style and eye range.

Read from the robot's parsed config (:class:`gazebot.core.kinematics.RobotConfig`, the one
parser of ``configs/robots/<name>.yaml``): ``display.width_px``/``height_px``, ``eye_style`` and
``eyes.yaw_range_deg``/``pitch_range_deg``. A robot name or YAML path is resolved through the
kinematics loader, so a custom robot YAML works wherever a shipped robot does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from gazebot.core.kinematics.robot_config import RobotConfig


@dataclass(frozen=True)
class RobotDisplay:
    """A head screen: size (px), eye style name and the eye range (rad, symmetric half-range)."""

    robot: str
    width: int
    height: int
    style: str
    yaw_range: float = math.radians(35.0)
    pitch_range: float = math.radians(25.0)
    source: str = "<robot config>"


def _half_range(range_deg: tuple[float, float]) -> float:
    """``[lo, hi]`` degrees -> the largest magnitude in rad (the renderer's eye travel is
    symmetric; the config guarantees lo <= 0 <= hi and |lo|, |hi| <= 89). Eyes without range
    (``[0, 0]``: they never move) keep the default scale, which then only draws them centred."""
    half = math.radians(max(abs(range_deg[0]), abs(range_deg[1])))
    return half if half > 0.0 else RobotDisplay.yaw_range


def robot_display(robot: str | Path | RobotConfig) -> RobotDisplay:
    """The display of a robot given by name (``sawyer``), robot YAML path or parsed config.

    Raises:
        FileNotFoundError: unknown robot name or missing YAML file.
        ConfigError: the robot YAML is malformed (names file, field and expectation).
    """
    # Imported here: the kinematics package pulls in Pinocchio, which the eye renderer alone
    # (e.g. ``gazebot render eyes --width --height``) does not need.
    from gazebot.core.kinematics.robot_config import RobotConfig, load_robot_config

    if isinstance(robot, RobotConfig):
        config, source = robot, f"<robot config {robot.name!r}>"
    else:
        config, path = load_robot_config(robot)
        source = str(path)
    eyes = config.eyes
    if config.display is None or eyes is None or config.eye_style is None:
        from gazebot.core.config import ConfigError

        raise ConfigError(source, "display", "a head screen with drawn eyes (display, eyes)")
    return RobotDisplay(
        robot=config.name,
        width=config.display.width_px,
        height=config.display.height_px,
        style=config.eye_style,
        yaw_range=_half_range(eyes.yaw_range_deg),
        pitch_range=_half_range(eyes.pitch_range_deg),
        source=source,
    )
