"""Configuration of the seed's chapter-5 Guided Policy Search (``configs/gps.yaml``).

Degrees appear only in fields ending in ``_deg``; the properties convert them to radians.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from gazebot.core.config import configs_dir, load_model


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class TesterConfig(_Strict):
    """The 2-DoF trainer/tester arm and its cylindrical hand, and eq. 5.12's coefficients."""

    shoulder_distance_m: float = Field(gt=0)
    shoulder_height_m: float
    upper_arm_m: float = Field(gt=0)
    forearm_m: float = Field(gt=0)
    hand_mass_kg: float = Field(gt=0)
    hand_radius_m: float = Field(gt=0)
    hand_length_m: float = Field(gt=0)
    rest_deg: tuple[float, float]
    a: float
    b: float = Field(gt=0)
    c: float = Field(gt=0)
    t_f_s: float = Field(gt=0)


class SceneConfig(_Strict):
    """The learner (Panda), the tester and the trial's timing."""

    trial_s: float = Field(gt=0)
    control_dt_s: float = Field(gt=0)
    timestep_s: float = Field(gt=0)
    ee_mass_kg: float = Field(gt=0)
    gripper_force_n: float = Field(gt=0)
    joint_damping: tuple[float, float, float, float, float, float, float]
    home_deg: tuple[float, float, float, float, float, float, float]
    tester: TesterConfig

    @model_validator(mode="after")
    def _steps(self) -> SceneConfig:
        ratio = self.control_dt_s / self.timestep_s
        if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
            raise ValueError("control_dt_s must be a whole multiple of timestep_s")
        return self

    @property
    def substeps(self) -> int:
        return int(round(self.control_dt_s / self.timestep_s))

    @property
    def horizon(self) -> int:
        """T: control steps per trial."""
        return int(round(self.trial_s / self.control_dt_s))

    @property
    def home_rad(self) -> tuple[float, ...]:
        return tuple(math.radians(v) for v in self.home_deg)


class ShellConfig(_Strict):
    """The semi-hemispherical shell of test locations around the learner's base (seed 5.4)."""

    azimuth_deg: tuple[float, float]
    azimuth_step_deg: float = Field(gt=0)
    radius_m: tuple[float, float]
    elevation_deg: tuple[float, float]
    grid: int = Field(ge=2)

    @model_validator(mode="after")
    def _ordered(self) -> ShellConfig:
        for name in ("azimuth_deg", "radius_m", "elevation_deg"):
            lo, hi = getattr(self, name)
            if not lo < hi:
                raise ValueError(f"{name} must be [low, high] with low < high")
        if self.radius_m[0] <= 0:
            raise ValueError("radius_m must be positive")
        return self


class GPSConfig(_Strict):
    """BADMM GPS hyper-parameters (section 5.2.1); see configs/gps.yaml for which are the seed's."""

    iterations: int = Field(ge=1)
    samples: int = Field(ge=2)
    alpha_reach: float = Field(gt=0)
    torque_weight: float = Field(gt=0)
    gripper_weight: float = Field(gt=0)
    init_kp: tuple[float, float, float, float, float, float, float]
    init_kd: tuple[float, float, float, float, float, float, float]
    init_std_frac: float = Field(gt=0)
    kl_step: float = Field(gt=0)
    gmm_clusters: int = Field(ge=1)
    prior_strength: float = Field(gt=0)
    prior_iterations: int = Field(ge=1)
    inner_iterations: int = Field(ge=1)
    nu_init: float = Field(gt=0)
    nu_max: float = Field(gt=0)
    kl_policy_target: float = Field(gt=0)
    dual_rate: float = Field(ge=0)
    hidden_units: int = Field(ge=1)
    learning_rate: float = Field(gt=0)
    policy_steps: int = Field(ge=1)
    batch: int = Field(ge=1)
    seed: int = 0
    # Which KL each BADMM step penalises: "levine" (default) fits the policy to KL(pi || p) and
    # bounds the trajectory step by KL(p || pi), as Levine et al.'s released code; "seed" uses
    # eqs. 5.5/5.6 as printed: KL(p || pi) in the policy step, KL(pi || p) in the trajectory step.
    kl_directions: Literal["levine", "seed"] = "levine"


class GPSFileConfig(_Strict):
    """The whole of ``configs/gps.yaml``."""

    scene: SceneConfig
    shell: ShellConfig
    gps: GPSConfig


def default_gps_path() -> Path:
    return configs_dir() / "gps.yaml"


def load_gps_config(path: str | Path | None = None) -> GPSFileConfig:
    """Load and validate a GPS configuration (default: the shipped ``configs/gps.yaml``)."""
    return load_model(GPSFileConfig, path or default_gps_path())
