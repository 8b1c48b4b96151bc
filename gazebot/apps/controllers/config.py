"""Configuration of the seed's reach controllers (``configs/controllers.yaml``, chapters 3 and 4).

The seed gives some values (section 4.4.2: ``eps_p = 0.01 m``, ``u`` in ``[-1, 1] m/s`` per axis,
``dt = 0.2 s``, ``H = 15``); the rest (``k_p``, ``L``, ``eps_x``, ``eps_u``, the handover zone
radius ``l_h``, the load-share thresholds ``delta_1``/``delta_2``) are our defaults, documented in
the YAML. Units are SI (m, s, m/s).
"""

from __future__ import annotations

from enum import Enum
from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field, model_validator

from gazebot.core.config import configs_dir, load_model


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class SpeedLimit(str, Enum):
    """How ``u_max`` caps the end-effector velocity."""

    PER_AXIS = "per_axis"  # |u_x|, |u_y|, |u_z| <= u_max (seed 4.4.2: u_min <= u <= u_max)
    NORM = "norm"  # ||u||_2 <= u_max (seed eq. 3.3b)


class Strategy(str, Enum):
    """The reach-phase strategies of the seed's Table 4.3."""

    PROACTIVE_PREDETERMINED = "proactive-predetermined"
    PROACTIVE_TOWARDS_HUMAN = "proactive-towards-human"
    REACTIVE_PREDETERMINED = "reactive-predetermined"
    REACTIVE_TOWARDS_HUMAN = "reactive-towards-human"

    @property
    def reactive(self) -> bool:
        return self.value.startswith("reactive")

    @property
    def towards_human(self) -> bool:
        return self.value.endswith("towards-human")


class Role(str, Enum):
    """The robot's role in the handover (Table 4.2 rows)."""

    RECEIVER = "receiver"  # human-to-robot: reach spec with t_1
    GIVER = "giver"  # robot-to-human: reach spec with t_7


class PVConfig(_Strict):
    """Proportional velocity baseline (eq. 3.6)."""

    k_p: float = Field(default=2.0, gt=0, description="proportional gain, 1/s")


class MPCConfig(_Strict):
    """Receding-horizon QP (MCJ eqs. 3.2-3.3, MCE eqs. 3.4-3.5)."""

    horizon: int = Field(default=20, ge=2, le=400, description="L, steps (grows to the deadline)")
    eps_x_m: float = Field(default=0.01, gt=0, description="position tolerance at the reach time")
    eps_u_m_s: float = Field(default=0.05, gt=0, description="velocity tolerance at the reach time")


class STLConfig(_Strict):
    """STL synthesis as a MILP (section 4.3, eqs. 4.1-4.5)."""

    horizon: int = Field(default=15, ge=2, le=100, description="H, steps")
    eps_p_m: float = Field(default=0.01, gt=0, description="l1 position tolerance")
    margin_m: float = Field(
        default=0.001, ge=0, description="synthesize near this far inside eps_p (robustness)"
    )
    strategy: Strategy = Strategy.REACTIVE_TOWARDS_HUMAN
    role: Role = Role.RECEIVER
    zone_radius_m: float = Field(
        default=2.0, gt=0, description="l_h: handover zone radius around the robot's base"
    )
    history_steps: int = Field(
        default=5, ge=2, le=100, description="hand samples for the least-squares LDS fit (eq. 4.5)"
    )
    force_sensor: bool = Field(
        default=True,
        description="Table 4.1: object states from the load share (True) or, without a gripper "
        "force sensor, from the object's distance to gripper and hand and their openness",
    )
    eps_g: float = Field(default=0.1, gt=0, le=1, description="openness tolerance (no sensor)")
    grip_width: float = Field(default=0.0, ge=0, le=1, description="g*: openness holding it")
    delta_1: float = Field(default=0.2, ge=0, le=1, description="load share: released at or below")
    delta_2: float = Field(default=0.8, ge=0, le=1, description="load share: held above")
    mip_gap: float = Field(default=1e-4, ge=0, lt=1)
    transfer_time_s: float = Field(
        default=1.0, gt=0, description="t_2 / t_8: grasp (or release) this soon in the transfer"
    )
    retreat_time_s: float = Field(
        default=2.5, gt=0, description="t_3 / t_9: at the drop-off (or home) this soon"
    )
    release_time_s: float = Field(
        default=1.0, gt=0, description="t_4: a receiver opens this soon at the drop-off"
    )
    pickup_time_s: float = Field(
        default=3.0, gt=0, description="t_5: a giver is at the object this soon once it is free"
    )
    pickup_grasp_time_s: float = Field(
        default=1.0, gt=0, description="t_6: a giver grasps this soon once at the object"
    )
    gripper_speed_per_s: float = Field(
        default=4.0,
        gt=0,
        le=100,
        description="|dg_r/dt| cap: gripper openness (0 closed .. 1 open) per second (eq. 4.2)",
    )
    gripper_margin: float = Field(
        default=0.02, ge=0, description="synthesize the openness this far inside eps_g"
    )

    @model_validator(mode="after")
    def _ordered(self) -> STLConfig:
        if self.margin_m >= self.eps_p_m:
            raise ValueError("margin_m < eps_p_m")
        if self.gripper_margin >= self.eps_g:
            raise ValueError("gripper_margin < eps_g")
        if self.delta_1 > self.delta_2:
            raise ValueError("delta_1 <= delta_2")
        return self


class ControllersConfig(_Strict):
    """Everything the reach controllers need; one object handed to whichever is selected."""

    u_max_m_s: float = Field(default=1.0, gt=0, le=5.0, description="end-effector speed cap")
    speed_limit: SpeedLimit = SpeedLimit.PER_AXIS
    dt_s: float = Field(default=0.2, gt=0, le=1.0, description="control period of the planners")
    reach_time_s: float = Field(default=3.0, gt=0, description="'Reach before' (t_r, t_1, t_7)")
    stall_time_s: float = Field(default=0.0, ge=0, description="'Don't move until' (MCE)")
    pv: PVConfig = Field(default_factory=PVConfig)
    mcj: MPCConfig = Field(default_factory=MPCConfig)
    mce: MPCConfig = Field(default_factory=MPCConfig)
    stl: STLConfig = Field(default_factory=STLConfig)

    @model_validator(mode="after")
    def _stall_before_reach(self) -> ControllersConfig:
        if self.stall_time_s >= self.reach_time_s:
            raise ValueError("stall_time_s must be shorter than reach_time_s")
        return self


def default_controllers_path() -> Path:
    return configs_dir() / "controllers.yaml"


def load_controllers_config(path: str | Path | None = None) -> ControllersConfig:
    """The controllers' configuration from ``path`` (default: ``configs/controllers.yaml``).

    Raises:
        ConfigError: the YAML does not validate (names the file and the field).
    """
    return load_model(ControllersConfig, path or default_controllers_path())
