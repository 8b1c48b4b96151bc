"""Which screen a robot's eyes are drawn on: resolution, eye style and eye range.

The robot YAML (``configs/robots/<name>.yaml``, written by the kinematics package) is the source of
truth. Its layout belongs to another package, so it is read tolerantly: any key path mentioning the
display/screen width, height or resolution, the eye style, and the eye yaw/pitch range (degrees)
is used; anything missing falls back to :data:`KNOWN_DISPLAYS`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from gazebot.config import ConfigError, configs_dir, read_yaml


@dataclass(frozen=True)
class RobotDisplay:
    """A head screen: size (px), eye style name and the eye range (rad, symmetric half-range)."""

    robot: str
    width: int
    height: int
    style: str
    yaw_range: float = math.radians(35.0)
    pitch_range: float = math.radians(25.0)
    source: str = "built-in table"


# Fallbacks when the robot YAML is absent or silent: Sawyer's 1024x600 head screen and the
# 7-inch 800x480 screen on the Jaco-2's head.
KNOWN_DISPLAYS: dict[str, RobotDisplay] = {
    "sawyer": RobotDisplay("sawyer", 1024, 600, "sawyer"),
    "jaco2": RobotDisplay("jaco2", 800, 480, "jaco2-head"),
}


def _flatten(data: Any, prefix: str = "") -> dict[str, Any]:
    """``{"display": {"width": 3}}`` -> ``{"display_width": 3}`` (lower case, ``_`` joined)."""
    out: dict[str, Any] = {}
    if isinstance(data, dict):
        for key, value in data.items():
            name = f"{prefix}_{key}".lower() if prefix else str(key).lower()
            out.update(_flatten(value, name))
    else:
        out[prefix] = data
    return out


def _find(flat: dict[str, Any], pattern: str) -> tuple[str, Any] | None:
    rx = re.compile(pattern)
    for key, value in flat.items():
        if rx.search(key):
            return key, value
    return None


def _positive_int(source: Path, key: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise ConfigError(source, key, "a positive number of pixels", value)
    return int(value)


def _half_range_rad(source: Path, key: str, value: Any) -> float:
    """A range in degrees: a symmetric half-range ``30`` or ``[lo, hi]`` (largest magnitude)."""
    if isinstance(value, dict):
        value = [value.get("min", value.get("lo")), value.get("max", value.get("hi"))]
    vals = value if isinstance(value, (list, tuple)) else [value]
    try:
        deg = max(abs(float(v)) for v in vals)
    except (TypeError, ValueError):
        raise ConfigError(source, key, "an eye range in degrees: 30 or [-30, 30]", value) from None
    if not math.isfinite(deg) or not 0 < deg < 90:
        raise ConfigError(source, key, "an eye half-range in (0, 90) degrees", value)
    return math.radians(deg)


def robot_display(name_or_path: str | Path) -> RobotDisplay:
    """The display of robot ``name`` (``"sawyer"``, ``"jaco2"``) or of a robot YAML path.

    Raises ``ValueError`` for a robot with neither a YAML nor a built-in entry, ``ConfigError`` for
    a YAML whose display fields are malformed.
    """
    text = str(name_or_path)
    path = Path(text)
    if not (path.suffix in (".yaml", ".yml") or path.is_file()):
        try:
            path = configs_dir() / "robots" / f"{text}.yaml"
        except FileNotFoundError:
            path = Path("<missing>")
    robot = path.stem if path.suffix in (".yaml", ".yml") else text
    base = KNOWN_DISPLAYS.get(robot)
    if not path.is_file():
        if Path(text).suffix in (".yaml", ".yml"):
            raise FileNotFoundError(f"robot file not found: {text}")
        if base is None:
            known = ", ".join(sorted(KNOWN_DISPLAYS))
            raise ValueError(f"unknown robot {text!r} for the eye display (known: {known})")
        return base
    data = read_yaml(path)
    flat = _flatten(data if isinstance(data, dict) else {})
    if isinstance(data, dict) and isinstance(data.get("name"), str):
        robot = data["name"]
        base = KNOWN_DISPLAYS.get(robot, base)
    info = base or RobotDisplay(robot, 0, 0, "sawyer")
    info = replace(info, robot=robot, source=str(path))

    res = _find(flat, r"(display|screen).*(resolution|size_px|_px)$")
    if res and isinstance(res[1], (list, tuple)) and len(res[1]) == 2:
        info = replace(
            info,
            width=_positive_int(path, res[0], res[1][0]),
            height=_positive_int(path, res[0], res[1][1]),
        )
    width = _find(flat, r"(display|screen).*width")
    height = _find(flat, r"(display|screen).*height")
    if width and not isinstance(width[1], (list, tuple, dict)):
        info = replace(info, width=_positive_int(path, width[0], width[1]))
    if height and not isinstance(height[1], (list, tuple, dict)):
        info = replace(info, height=_positive_int(path, height[0], height[1]))
    style = _find(flat, r"(^|_)(eye_?style|eyes_style)$") or _find(flat, r"eye.*style")
    if style and isinstance(style[1], str) and style[1]:
        info = replace(info, style=style[1])
    yaw = _find(flat, r"eye.*yaw.*(range|limit)") or _find(flat, r"eye.*(range|limit).*yaw")
    pitch = _find(flat, r"eye.*pitch.*(range|limit)") or _find(flat, r"eye.*(range|limit).*pitch")
    if yaw:
        info = replace(info, yaw_range=_half_range_rad(path, yaw[0], yaw[1]))
    if pitch:
        info = replace(info, pitch_range=_half_range_rad(path, pitch[0], pitch[1]))
    if info.width <= 0 or info.height <= 0:
        raise ConfigError(path, "display", "the head screen's width and height in pixels")
    return info
