"""The robot YAML (``configs/robots/<name>.yaml``): a pydantic model, degrees at the surface.

The YAML is shared: the simulation reads ``mjcf``, ``head_joints``, ``arm_joints``,
``arm_home_deg``, ``arm_handover_deg`` and ``gripper_actuator``; the eye renderer reads
``display`` and ``eyes``; the gaze engine reads everything else. Joint position limits are not
repeated here: the model (``mjcf:`` or ``urdf:``) is their single source, and of velocity limits
unless ``head_velocity_limits_deg_s`` overrides them (docs/your-robot.md). A YAML without
``mjcf:`` and ``urdf:`` describes a robot whose URDF comes from its running stack
(``gazebot run --robot-description``, :meth:`RobotModel.from_urdf_text`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from gazebot.core.config import ConfigError, configs_dir, load_model
from gazebot.core.kinematics.model_files import package_search_path, resolve_model_path
from gazebot.core.kinematics.shifts import GazeShiftConfig

REQUIRED_POINTS = ("face", "handover_location", "rest")

#: How the robot points its gaze: ``head-and-eyes`` (the neck turns and the display's eyes take
#: the rest), ``head-only`` (the display shows fixed eyes; seed 6.3: "a static image of two eyes")
#: or ``eyes-only`` (the neck holds still; seed 6.4: "robot eye gazes instead of head gazes").
GazeMode = Literal["head-and-eyes", "head-only", "eyes-only"]
GAZE_MODES: tuple[str, ...] = ("head-and-eyes", "head-only", "eyes-only")


class DisplayConfig(BaseModel):
    """The head screen."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    width_px: int = Field(gt=0)
    height_px: int = Field(gt=0)
    diagonal_in: float = Field(gt=0.0)


class EyeConfig(BaseModel):
    """Range and speed of the eyes drawn on the display (degrees).

    Yaw is about the gaze frame's +z (positive = robot's left), pitch about +y (positive = down).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    yaw_range_deg: tuple[float, float]
    pitch_range_deg: tuple[float, float]
    velocity_limit_deg_s: float = Field(600.0, gt=0.0)

    @field_validator("yaw_range_deg", "pitch_range_deg")
    @classmethod
    def _range(cls, value: tuple[float, float]) -> tuple[float, float]:
        lo, hi = value
        # [0, 0] is allowed: eyes that cannot move (e.g. a static image of two eyes).
        if not -89.0 <= lo <= 0.0 <= hi <= 89.0:
            raise ValueError("[min, max] degrees with -89 <= min <= 0 <= max <= 89")
        return value


Point = tuple[float, float, float]


class GazeFrameConfig(BaseModel):
    """The gaze frame as a fixed offset from a link of the model (``gaze_frame:``).

    The frame's +x is the line of sight, +y the robot's left, +z up (the display's up).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    link: str = Field(min_length=1)
    xyz: Point = (0.0, 0.0, 0.0)
    rpy_deg: Point = (0.0, 0.0, 0.0)


class EyeJointsConfig(BaseModel):
    """Eyes that are joints of the model (``eye_joints:``): the joints that turn them left/right
    (one per eye) and up/down (one per eye, or one shared). Their ranges and speeds come from
    the model."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    yaw: list[str] = Field(min_length=1)
    pitch: list[str] = Field(min_length=1)

    @property
    def names(self) -> list[str]:
        """All eye joints, yaw joints first."""
        return list(self.yaw) + [n for n in self.pitch if n not in self.yaw]


class IKSettings(BaseModel):
    """The look-at solver's settings (``ik:``), degrees and metres at the surface.

    A field left out takes the solver's default (:class:`gazebot.core.kinematics.IKConfig`, the one
    place the defaults live; it holds the same settings in SI units).

    Attributes:
        damping: Levenberg damping lambda (rad^2) of the least-squares step.
        max_iterations: Iteration cap of one solve (a warm start typically needs 1-3).
        tolerance_deg: Head pointing error (deg) at which a solve stops.
        tracking_tolerance_deg: Looser stop (deg) while following a target that moved slightly.
        goal_deadband_deg: The gaze controller keeps the head goal while a tracked target's
            direction, seen from the goal's gaze origin, stays within this angle (deg) of the
            one the goal was solved for; the eyes take the difference as far as their range
            allows. 0 re-solves every move.
        max_step_deg: Largest joint change per iteration (deg); keeps far targets stable.
        min_step_deg: A step smaller than this (deg) means the head cannot do better.
        posture_gain: Null-space pull toward the rest posture per iteration (0..1).
        posture_off_deg: Reducible pointing error (deg) below which the posture pull stops.
        min_distance_m: Targets closer than this to the gaze origin (m) have no direction.
        max_distance_m: Targets farther than this from the base origin (m) are invalid samples.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    damping: float | None = Field(None, gt=0.0)
    max_iterations: int | None = Field(None, ge=1)
    tolerance_deg: float | None = Field(None, gt=0.0)
    tracking_tolerance_deg: float | None = Field(None, gt=0.0)
    goal_deadband_deg: float | None = Field(None, ge=0.0)
    max_step_deg: float | None = Field(None, gt=0.0)
    min_step_deg: float | None = Field(None, gt=0.0)
    posture_gain: float | None = Field(None, ge=0.0, le=1.0)
    posture_off_deg: float | None = Field(None, gt=0.0)
    min_distance_m: float | None = Field(None, gt=0.0)
    max_distance_m: float | None = Field(None, gt=0.0)


class RobotConfig(BaseModel):
    """A robot for gazebot: its model (MJCF or URDF), head and arm joints, poses, eyes and
    default points."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    name: str = Field(min_length=1)
    mjcf: str | None = Field(default=None, min_length=1)
    urdf: str | None = Field(default=None, min_length=1)
    # The ROS frame name of the base frame every point is in (the MJCF world frame); what
    # gaze targets and tracking on the ROS 2 wire carry as ``header.frame_id``.
    base_frame: str = Field(default="world", min_length=1)
    # The gaze frame: a frame of the model by name (an MJCF site, a URDF link), or, with
    # ``gaze_frame``, the name given to a frame added at an offset from a link.
    gaze_site: str = "gaze"
    gaze_frame: GazeFrameConfig | None = None
    gripper_site: str = "gripper"
    gripper_actuator: str = "gripper"
    eye_style: str | None = Field(default=None, min_length=1)
    display: DisplayConfig | None = None  # none: no head screen
    eye_joints: EyeJointsConfig | None = None  # eyes that are joints of the model
    head_joints: list[str] = Field(default_factory=list)  # none: a fixed head (eyes only)
    head_velocity_limits_deg_s: dict[str, float] = Field(default_factory=dict)
    head_rest_deg: dict[str, float] = Field(default_factory=dict)
    arm_joints: list[str] = Field(default_factory=list)  # none: a head without an arm
    arm_home_deg: dict[str, float] = Field(default_factory=dict)
    arm_handover_deg: dict[str, float] = Field(default_factory=dict)
    eyes: EyeConfig | None = None  # the drawn eyes (with ``display``); none: no movable eyes
    shifts: GazeShiftConfig = Field(default_factory=lambda: GazeShiftConfig.model_validate({}))
    ik: IKSettings = Field(default_factory=lambda: IKSettings.model_validate({}))
    gaze_mode: GazeMode = "head-and-eyes"
    points: dict[str, Point]
    # Tracked points farther than this from the robot base are implausible (a tracker's glitch,
    # a unit error): the engine treats them as missing samples (counted).
    workspace_radius_m: float = Field(default=4.0, gt=0.0, allow_inf_nan=False)

    @model_validator(mode="after")
    def _consistent(self) -> RobotConfig:
        if self.mjcf is not None and self.urdf is not None:
            raise ValueError("exactly one model file: 'mjcf: FILE' or 'urdf: FILE' (or neither, "
                             "for the URDF of a running stack: gazebot run --robot-description)")
        if self.display is not None and (self.eyes is None or self.eye_style is None):
            raise ValueError("'eyes' and 'eye_style' with a 'display' (the eyes drawn on it)")
        if self.eye_joints is not None and (self.display is not None or self.eyes is not None):
            raise ValueError("either eyes on a 'display' (with 'eyes') or 'eye_joints', not both")
        head = set(self.head_joints)
        if len(head) != len(self.head_joints):
            raise ValueError("head_joints without duplicates")
        if head & set(self.arm_joints):
            raise ValueError("head_joints and arm_joints to be disjoint")
        eye = set(self.eye_joints.names) if self.eye_joints is not None else set()
        if eye & (head | set(self.arm_joints)):
            raise ValueError("eye_joints apart from head_joints and arm_joints")
        unknown = set(self.head_velocity_limits_deg_s) - head - eye
        if unknown:
            raise ValueError(f"head_velocity_limits_deg_s only for head or eye joints ({unknown})")
        if any(not v > 0.0 for v in self.head_velocity_limits_deg_s.values()):
            raise ValueError("positive head velocity limits")
        unknown = set(self.head_rest_deg) - head
        if unknown:
            raise ValueError(f"head_rest_deg only for head joints (unknown {unknown})")
        for key in ("arm_home_deg", "arm_handover_deg"):
            pose = getattr(self, key)
            if set(pose) != set(self.arm_joints):
                raise ValueError(f"{key} with exactly the arm joints {self.arm_joints}")
        missing_points = [p for p in REQUIRED_POINTS if p not in self.points]
        if missing_points:
            raise ValueError(f"points including {missing_points}")
        return self


def robot_config_path(name_or_yaml: str | Path) -> Path:
    """``sawyer`` -> ``configs/robots/sawyer.yaml``; a ``.yaml`` path is returned as is."""
    path = Path(name_or_yaml)
    if path.suffix in (".yaml", ".yml"):
        if not path.is_file():
            raise FileNotFoundError(f"robot file not found: {path}")
        return path
    folder = configs_dir() / "robots"
    path = folder / f"{name_or_yaml}.yaml"
    if not path.is_file():
        known = ", ".join(sorted(p.stem for p in folder.glob("*.yaml"))) or "none"
        raise FileNotFoundError(f"unknown robot {str(name_or_yaml)!r} (known: {known})")
    return path


def load_robot_config(name_or_yaml: str | Path) -> tuple[RobotConfig, Path]:
    """Load and validate a robot YAML by name or path; returns the config and its file.

    Raises:
        FileNotFoundError: no such robot / file.
        ConfigError: the YAML is malformed (names file, field and expectation).
    """
    path = robot_config_path(name_or_yaml)
    return load_model(RobotConfig, path), path


def with_gaze_mode(robot: str | Path | RobotConfig, mode: str | None) -> str | Path | RobotConfig:
    """``robot`` (name, YAML path or config) with its ``gaze_mode`` replaced; ``None`` returns
    ``robot`` unchanged. The result is a :class:`RobotConfig` whose MJCF path is absolute, so it
    loads like the original (the CLI's ``--gaze-mode``).

    Raises:
        ValueError: ``mode`` is not one of :data:`GAZE_MODES`.
    """
    if mode is None:
        return robot
    if mode not in GAZE_MODES:
        raise ValueError(f"gaze mode one of {', '.join(GAZE_MODES)}, not {mode!r}")
    if isinstance(robot, RobotConfig):
        config, path = robot, None
    else:
        config, path = load_robot_config(robot)
    data = config.model_dump()
    data.update(gaze_mode=mode)
    if config.mjcf is not None:
        data.update(mjcf=str(resolve_mjcf(config, path).resolve()))
    elif config.urdf is not None:
        data.update(urdf=str(resolve_model_file(config, path)[0]))
    return RobotConfig.model_validate(data)


def with_package_path(
    robot: str | Path | RobotConfig, package_path: list[str] | tuple[str, ...] = ()
) -> RobotConfig:
    """``robot`` (name, YAML path or config) with its model file resolved to an absolute path
    (``package://`` URIs looked up in ``package_path`` first, then the usual folders), so it
    loads wherever it is passed (the CLI's ``--package-path``).

    Raises:
        FileNotFoundError: unknown robot / file.
        ConfigError: malformed YAML, or the model file is not found.
    """
    if isinstance(robot, RobotConfig):
        config, path = robot, None
    else:
        config, path = load_robot_config(robot)
    if config.mjcf is None and config.urdf is None:
        return config  # its URDF comes from the running stack
    found, kind = resolve_model_file(config, path, package_path)
    return config.model_copy(update={kind: str(found)})


def resolve_model_file(
    config: RobotConfig, yaml_path: Path | None, package_path: list[str] | tuple[str, ...] = ()
) -> tuple[Path, str]:
    """The model file of ``config`` and its kind (``"mjcf"`` or ``"urdf"``).

    Raises:
        ConfigError: the file is not found (names the YAML, the field and where it looked), or
            the YAML names none (its URDF comes from the stack).
    """
    kind = "mjcf" if config.mjcf is not None else "urdf"
    raw = config.mjcf if config.mjcf is not None else config.urdf
    if raw is None:
        raise ConfigError(
            yaml_path or "<robot config>", "urdf", "a model file ('urdf: FILE' or 'mjcf: FILE'); "
            "without one, the URDF comes from the stack: gazebot run --robot-description")
    search = package_search_path(package_path)
    found, expected = resolve_model_path(raw, yaml_path, search, assets=kind == "mjcf")
    if found is None:
        raise ConfigError(yaml_path or "<robot config>", kind, expected, raw)
    return found, kind


def resolve_mjcf(config: RobotConfig, yaml_path: Path | None) -> Path:
    """The MJCF file of ``config``: absolute, beside the YAML, or in ``gazebot/assets/robots/``.

    Raises:
        ConfigError: no such file, or the robot is described by a URDF (the MuJoCo simulation
            of the handover scene needs an MJCF).
    """
    if config.mjcf is None:
        raise ConfigError(
            yaml_path or "<robot config>", "mjcf", "an MJCF model (this robot has a URDF)",
            config.urdf,
        )
    return resolve_model_file(config, yaml_path)[0]
