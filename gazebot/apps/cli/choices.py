"""The options every command names a robot, behavior or scene with: their help lists what the
registries (:func:`gazebot.apps.cli.registries.registries`) hold today, so a robot added as a YAML
file shows up in every ``--help`` without editing one."""

from __future__ import annotations

import argparse

from gazebot.apps.cli.registries import registries
from gazebot.core.config import ConfigError
from gazebot.core.defaults import DEFAULT_ROBOT


def known_names(kind: str) -> str:
    """The registered names of ``kind`` (a key of :func:`registries`), comma-separated; a
    user's broken YAML file in a listed folder leaves the help with a pointer instead (the
    command that loads it reports the file)."""
    try:
        return ", ".join(registries()[kind].names())
    except (ConfigError, OSError):
        return f"see gazebot {kind} list" if kind == "behaviors" else "see the configs folder"


def add_robot_argument(
    parser: argparse.ArgumentParser, *, default: str | None = DEFAULT_ROBOT,
    default_help: str | None = None,
) -> None:
    """``--robot NAME|YAML`` (default ``default``; ``default_help`` says it in words when the
    default is decided later, e.g. from another option)."""
    parser.add_argument(
        "--robot", default=default,
        help=f"robot name ({known_names('robots')}) or a robot YAML file (URDF or MJCF robots: "
        f"docs/your-robot.md) (default: {default_help or default})",
    )


def add_behavior_argument(
    parser: argparse.ArgumentParser, *, default: str | None = None, what: str = "gaze behavior",
    **kwargs: object,
) -> None:
    """``--behavior NAME|YAML``; ``default=None`` with ``required=True`` in ``kwargs`` makes it
    mandatory, ``action="append"`` repeatable."""
    tail = f" (default: {default})" if default is not None else ""
    parser.add_argument(
        "--behavior", default=default,
        help=f"{what}: a name ({known_names('behaviors')}) or a behavior YAML file{tail}",
        **kwargs,  # type: ignore[arg-type]
    )


def scene_help(default: str | None = "default") -> str:
    """The help of a scene option: the shipped scenes and the default."""
    tail = f" (default: {default})" if default is not None else ""
    return f"scene name ({known_names('scenes')}) or a scene YAML file{tail}"


def add_scene_argument(parser: argparse.ArgumentParser, *, default: str = "default") -> None:
    """``--scene NAME|YAML`` (default: the ``default`` scene)."""
    parser.add_argument("--scene", default=default, help=scene_help(default))


def add_gaze_mode_argument(parser: argparse.ArgumentParser) -> None:
    """``--gaze-mode``: how the robot points its gaze (default: the robot YAML's)."""
    parser.add_argument(
        "--gaze-mode",
        default=None,
        help="how the robot points its gaze: head-and-eyes, head-only "
        "(fixed display eyes) or eyes-only (head held still); default: the robot YAML",
    )
