"""Scene configuration (``configs/scenes/*.yaml``): the giver's posture and timing, the object, the
robot's handover controller and the tracking noise. Durations are seconds; angles at this YAML
surface are degrees (``*_deg``)."""

from __future__ import annotations

from enum import Enum
from pathlib import Path

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from gazebot.apps.controllers import GPS
from gazebot.core.config import configs_dir, load_model


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class Posture(str, Enum):
    STANDING = "standing"
    SITTING = "sitting"


class ObjectKind(str, Enum):
    SMALL_BOX = "small_box"
    LARGE_BOX = "large_box"
    PLASTIC_BOTTLE = "plastic_bottle"
    GLASS_BOTTLE = "glass_bottle"


class DurationModel(_Strict):
    """A duration drawn from a normal distribution clipped to ``[min_s, max_s]``."""

    mean_s: float = Field(gt=0)
    sd_s: float = Field(ge=0)
    min_s: float = Field(gt=0)
    max_s: float = Field(gt=0)

    @model_validator(mode="after")
    def _ordered(self) -> DurationModel:
        if not self.min_s <= self.mean_s <= self.max_s:
            raise ValueError("min_s <= mean_s <= max_s")
        return self

    def sample(self, rng: np.random.Generator) -> float:
        return float(np.clip(rng.normal(self.mean_s, self.sd_s), self.min_s, self.max_s))


# Phase durations of the 288 annotated human-human handovers (seed section 6.2, 8 fps):
# reach 0.99 +- 0.24 s, transfer 0.59 +- 0.22 s, retreat 1.05 +- 0.26 s (mean +- sd).
def _reach() -> DurationModel:
    return DurationModel(mean_s=0.99, sd_s=0.24, min_s=0.6, max_s=2.0)


def _transfer() -> DurationModel:
    return DurationModel(mean_s=0.59, sd_s=0.22, min_s=0.25, max_s=1.75)


def _retreat() -> DurationModel:
    return DurationModel(mean_s=1.05, sd_s=0.26, min_s=0.5, max_s=2.1)


class GiverConfig(_Strict):
    """The simulated giver: where it stands and how long each of its motions takes."""

    height_m: float = Field(default=1.75, ge=1.4, le=2.1)
    standoff_m: float = Field(
        default=0.42, ge=0.2, le=0.6, description="shoulder ahead of the handover location (+x)"
    )
    start_delay_s: float = Field(default=1.0, ge=0.0, description="idle time before the reach")
    start_jitter_s: float = Field(default=0.2, ge=0.0, description="uniform +- jitter of the start")
    reach: DurationModel = Field(default_factory=_reach)
    transfer: DurationModel = Field(default_factory=_transfer)
    retreat: DurationModel = Field(default_factory=_retreat)
    reaction_time_s: float = Field(
        default=0.3,
        ge=0.0,
        le=3.0,
        description="robot-initiated scenes: the giver starts this long after the robot's reach",
    )


#: The reach without a controller: a joint-space minimum-jerk move to the predefined handover
#: pose (the gaze studies' robot).
JOINT_REACH = "joint"
GPS_REACH = GPS  # the learned reach: needs controller.policy


def reach_controller_names() -> tuple[str, ...]:
    """How the robot may reach: ``joint`` or a registered controller (seed chapters 3-4;
    :data:`gazebot.apps.controllers.CONTROLLERS`)."""
    from gazebot.apps.controllers import CONTROLLERS

    return (JOINT_REACH, *CONTROLLERS.names())


class RetreatTrigger(str, Enum):
    """When the robot retreats home: after the giver releases the object (seed 6.3: "after the
    human released the object and started to retreat") or right after grasping it (6.4.3: "The
    robot retreated to its home position after grasping the object")."""

    AFTER_RELEASE = "after-release"
    AFTER_GRASP = "after-grasp"


class Initiator(str, Enum):
    """Who starts the handover: the giver (the robot reacts to the giver's reach) or the robot
    (seed 6.3: the robot starts its reach, the giver responds after a reaction time)."""

    GIVER = "giver"
    ROBOT = "robot"


class Direction(str, Enum):
    """Who gives: the human (human-to-robot, the gaze studies) or the robot (robot-to-human, the
    seed's chapter 3 task: the simulated person takes the object from the robot)."""

    HUMAN_TO_ROBOT = "human-to-robot"
    ROBOT_TO_HUMAN = "robot-to-human"


class ControllerConfig(_Strict):
    """The robot's handover controller (seed 6.3.2/6.4.3): reach once the handover starts, grasp
    when the object is close, retreat home after the giver lets go (or after grasping)."""

    reach_controller: str = JOINT_REACH  # joint or a registered controller

    @field_validator("reach_controller")
    @classmethod
    def _known_controller(cls, value: str) -> str:
        if value == JOINT_REACH:
            return value
        from gazebot.apps.controllers import CONTROLLERS

        try:
            return CONTROLLERS.check(value)
        except ValueError:
            raise ValueError(
                f"one of {', '.join(reach_controller_names())}, got {value!r}"
            ) from None
    reach_time_s: float | None = Field(
        default=None, gt=0, description="'Reach before' from the handover's start (None: YAML)"
    )
    stall_time_s: float | None = Field(
        default=None, ge=0, description="'Don't move until' (mce; None: configs/controllers.yaml)"
    )
    controllers: str | None = Field(
        default=None, description="controllers YAML (None: configs/controllers.yaml)"
    )
    policy: str | None = Field(
        default=None, description="gps: the policy directory `gazebot gps train --out` wrote"
    )
    retreat: RetreatTrigger = RetreatTrigger.AFTER_RELEASE
    robot_start_s: float = Field(
        default=1.0, ge=0.0, description="robot-initiated scenes: when the robot starts its reach"
    )

    reach_min_duration_s: float = Field(default=1.6, gt=0)
    retreat_min_duration_s: float = Field(default=1.6, gt=0)
    max_joint_speed_deg: float = Field(default=120.0, gt=0, description="peak joint speed, deg/s")
    start_trigger_m: float = Field(default=0.04, gt=0, description="giver hand travel that starts")
    grasp_distance_m: float = Field(default=0.05, gt=0, description="object-gripper distance")
    gripper_close_s: float = Field(default=0.35, gt=0)
    release_trigger_m: float = Field(default=0.04, gt=0, description="hand-object gap = let go")
    pickup_m: tuple[float, float, float] | None = Field(
        default=None,
        description="robot-to-human, stl: the object starts here (robot base frame, m) and the "
        "robot picks it up first (seed Table 4.2, t_5 and t_6)",
    )
    dropoff_m: tuple[float, float, float] | None = Field(
        default=None,
        description="human-to-robot, stl: the robot carries the object here (robot base frame, "
        "m) and lets go of it (seed Table 4.2, t_3 and t_4)",
    )


class TrackingNoiseConfig(_Strict):
    """Motion-capture realism: isotropic Gaussian noise and random dropped samples."""

    noise_m: float = Field(default=0.0, ge=0.0, le=0.1)
    dropout_rate: float = Field(default=0.0, ge=0.0, lt=1.0)


class InsetCorner(str, Enum):
    TOP_LEFT = "top-left"
    TOP_RIGHT = "top-right"
    BOTTOM_LEFT = "bottom-left"
    BOTTOM_RIGHT = "bottom-right"


class InsetConfig(_Strict):
    """A close-up of the robot's head screen (the display texture as the eyes are drawn) pasted
    into a corner of the observer's frames, so the eyes read at any camera angle."""

    enabled: bool = True
    width_frac: float = Field(default=0.28, ge=0.1, le=0.5, description="of the frame width")
    corner: InsetCorner = InsetCorner.BOTTOM_LEFT


class CameraConfig(_Strict):
    """Observer camera. By default it stands ``distance_m`` from the robot's head (its gaze site
    at the home pose) in the direction ``azimuth_deg`` (about the vertical, from the robot's +x
    toward the giver, positive to the robot's left) and ``elevation_deg`` (above the head), and
    it aims and zooms so that the giver's face and hand, the object and the robot's head and arm
    fill the frame. ``None``: derived from the robot (see ``gazebot.apps.sim.scene``). ``pos_m`` /
    ``look_at_m`` place it explicitly (robot base frame, m); ``fovy_deg`` fixes the zoom."""

    pos_m: tuple[float, float, float] | None = None
    look_at_m: tuple[float, float, float] | None = None
    azimuth_deg: float | None = Field(default=None, ge=-180.0, le=180.0)
    elevation_deg: float | None = Field(default=None, ge=-60.0, le=80.0)
    distance_m: float | None = Field(default=None, gt=0.5, le=10.0)
    fovy_deg: float | None = Field(default=None, gt=5, lt=150, description="None: fit the scene")
    margin: float = Field(default=0.05, ge=0.0, le=0.4, description="frame kept free at edges")
    inset: InsetConfig = Field(default_factory=InsetConfig)


class GiverMotionConfig(_Strict):
    """A recorded giver to replay instead of the simulated one (``--giver-motion``; see
    :mod:`gazebot.apps.sim.giver_replay`): any recording format, with its point names."""

    file: str = Field(description="recording: CSV, C3D, ROS bag or pose folder")
    giver_hand: str | None = None
    receiver_hand: str | None = None
    giver_face: str | None = None
    unit: str | None = Field(default=None, description="m, cm or mm (CSV / pose folder)")
    rate_hz: float | None = Field(default=None, gt=0, description="pose-folder rate")


class SceneConfig(_Strict):
    """One handover setup (seed Table 6.3 conditions: object size, fragility, posture)."""

    name: str = "default"
    description: str = ""
    posture: Posture = Posture.STANDING
    object: ObjectKind = ObjectKind.SMALL_BOX
    table: bool | None = Field(default=None, description="None: a table when sitting")
    initiator: Initiator = Initiator.GIVER
    direction: Direction = Direction.HUMAN_TO_ROBOT
    giver: GiverConfig = Field(default_factory=GiverConfig)
    controller: ControllerConfig = Field(default_factory=ControllerConfig)
    tracking: TrackingNoiseConfig = Field(default_factory=TrackingNoiseConfig)
    camera: CameraConfig = Field(default_factory=CameraConfig)
    tail_s: float = Field(default=1.2, ge=0.0, description="video time kept after the handover")
    giver_motion: GiverMotionConfig | None = Field(
        default=None, description="replay a recorded giver instead of the simulated one"
    )

    @model_validator(mode="after")
    def _whole_task(self) -> SceneConfig:
        ctrl = self.controller
        for field, direction in (
            ("pickup_m", Direction.ROBOT_TO_HUMAN),
            ("dropoff_m", Direction.HUMAN_TO_ROBOT),
        ):
            if getattr(ctrl, field) is None:
                continue
            if ctrl.reach_controller != "stl":
                raise ValueError(f"controller.{field} needs reach_controller: stl (Table 4.2)")
            if self.direction is not direction:
                raise ValueError(f"controller.{field} needs direction: {direction.value}")
        if ctrl.reach_controller == GPS_REACH and ctrl.policy is None:
            raise ValueError("controller.policy (a directory from `gazebot gps train --out DIR`)"
                             " is needed by reach_controller: gps")
        if ctrl.policy is not None and ctrl.reach_controller != GPS_REACH:
            raise ValueError("controller.policy is the gps controller's: it needs "
                             "reach_controller: gps")
        if ctrl.reach_controller == GPS_REACH and self.direction is Direction.ROBOT_TO_HUMAN:
            raise ValueError("reach_controller: gps was trained to reach a person's hand to take"
                             " from it: it needs direction: human-to-robot")
        return self

    @property
    def has_table(self) -> bool:
        return self.posture is Posture.SITTING if self.table is None else self.table


def scenes_dir() -> Path:
    return configs_dir() / "scenes"


def scene_names() -> list[str]:
    """Names of the shipped scenes (``configs/scenes/<name>.yaml``)."""
    return sorted(p.stem for p in scenes_dir().glob("*.yaml"))


def load_scene(scene: str | Path | SceneConfig = "default") -> SceneConfig:
    """Load a scene by name (``configs/scenes/<name>.yaml``) or YAML path.

    Raises:
        FileNotFoundError: unknown name or missing file (the message lists the known scenes).
        ConfigError: the YAML does not validate.
    """
    if isinstance(scene, SceneConfig):
        return scene
    path = Path(scene)
    if path.suffix not in (".yaml", ".yml"):
        path = scenes_dir() / f"{scene}.yaml"
    if not path.is_file():
        raise FileNotFoundError(
            f"unknown scene {str(scene)!r}: no file {path} "
            f"(known scenes: {', '.join(scene_names())})"
        )
    return load_model(SceneConfig, path)


def with_inset(scene: str | Path | SceneConfig, enabled: bool) -> SceneConfig:
    """``scene`` (name, YAML path or config) with the observer's screen close-up on or off."""
    cfg = load_scene(scene)
    camera = cfg.camera.model_copy(
        update={"inset": cfg.camera.inset.model_copy(update={"enabled": bool(enabled)})}
    )
    return cfg.model_copy(update={"camera": camera})
