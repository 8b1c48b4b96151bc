"""Arms driven by joint torque motors (the Panda learner): position goals (home, the retreat,
holding still, the Cartesian reaches' IK) become torques through a joint impedance law,
``tau = K_p (q_goal - q) - K_d dq``, clipped to the motors' bounds and evaluated every physics
step; the robot's own gravity compensation (MJCF ``gravcomp``) carries the arm's weight, as the
Panda's controller does beneath its torque interface. Gains are the robot MJCF's custom numerics
``arm_impedance_kp`` and ``arm_impedance_kd`` (one per arm joint)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from gazebot.core.config import ConfigError


def arm_actuator(model: mujoco.MjModel, joint: str) -> int:
    """The actuator named ``joint``, else the one whose transmission is that joint (-1: none)."""
    act = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, joint)
    if act >= 0:
        return act
    jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
    for a in range(model.nu):
        if (int(model.actuator_trntype[a]) == int(mujoco.mjtTrn.mjTRN_JOINT)
                and int(model.actuator_trnid[a, 0]) == jid):
            return a
    return -1


def is_torque_motor(model: mujoco.MjModel, act: int) -> bool:
    """Whether actuator ``act`` applies its control as a force (a ``motor``: no bias)."""
    return (int(model.actuator_biastype[act]) == int(mujoco.mjtBias.mjBIAS_NONE)
            and int(model.actuator_gaintype[act]) == int(mujoco.mjtGain.mjGAIN_FIXED))


@dataclass(frozen=True)
class JointImpedance:
    """Position goals as torques on a torque-motor arm (N m/rad, N m s/rad, N m)."""

    kp: np.ndarray
    kd: np.ndarray
    tau_max: np.ndarray

    def torque(self, goal: np.ndarray, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
        """``K_p (goal - q) - K_d dq`` within +-``tau_max``; a non-finite goal holds ``q``."""
        goal = np.where(np.isfinite(goal), goal, q)
        tau = self.kp * (goal - q) - self.kd * dq
        return np.clip(tau, -self.tau_max, self.tau_max)


def impedance_from_model(model: mujoco.MjModel, acts: np.ndarray, mjcf: Path) -> JointImpedance:
    """The arm's impedance gains from the model's custom numerics, bounds from the motors.

    Raises:
        ConfigError: a gain vector is missing, of the wrong length or not positive.
    """
    gains = []
    for name in ("arm_impedance_kp", "arm_impedance_kd"):
        nid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name)
        if nid < 0:
            raise ConfigError(mjcf, name, f"a custom numeric with {len(acts)} gains for the "
                              "torque-motor arm")
        adr, size = int(model.numeric_adr[nid]), int(model.numeric_size[nid])
        values = np.array(model.numeric_data[adr:adr + size], float)
        if size != len(acts) or not np.all(values > 0):
            raise ConfigError(mjcf, name, f"{len(acts)} positive gains", values.tolist())
        gains.append(values)
    return JointImpedance(gains[0], gains[1], np.abs(model.actuator_ctrlrange[acts, 1]))
