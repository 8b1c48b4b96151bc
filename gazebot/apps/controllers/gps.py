"""``gps``: the seed's learned reach (chapter 5), a Guided Policy Search global policy trained by
``gazebot gps train --out DIR``, acting on a robot in the handover scene.

The policy maps the learner's state to the Panda's seven joint torques (eq. 5.8-5.10; the 8th
output, the gripper force, is not used: the handover controller closes the gripper at the grasp
distance, as the seed's trials did: "The gripper's actions were triggered based on a distance
threshold from the human's hand", 4.4.4). It plans no Cartesian velocities, so it runs only where
a torque-controlled Panda learner is (``--robot panda``, :mod:`gazebot.apps.sim.policy_reach`).

The state from the handover scene, in the arm's base frame (the frame the policy was trained in):
the arm's joints, velocities and gripper as measured; the tester's hand ``p_h`` is the reach goal
every controller gets (the object in the giver's hand); the three object points ``p_o`` are the
tester's cylinder posed by the tester's own IK with its hand at ``p_h`` (the GPS scene computes
them, so they are what training saw for a hand there); velocities are differences over one
control period. FULL states also need the tester's joint angles, which a person's arm does not
have: such a policy is rejected.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gazebot.apps.controllers import GPS
from gazebot.apps.controllers.config import ControllersConfig, load_controllers_config

#: The state fields the handover scene cannot give (FULL, eq. 5.8).
MISSING_IN_HANDOVER = "theta_h, dtheta_h (the 2-DoF tester's joint angles and velocities)"


@dataclass(frozen=True)
class LearnerState:
    """The learner as measured, in its arm's base frame (m, rad, s)."""

    theta_r: np.ndarray  # (7,) joint angles
    dtheta_r: np.ndarray  # (7,) joint velocities
    p_r: np.ndarray  # (3,) gripper (fingertip centre)
    dp_r: np.ndarray  # (3,)
    r_ee: np.ndarray  # (3, 3) gripper frame
    w_ee: np.ndarray  # (3,) gripper angular velocity
    g_r: float  # gripper width (m)


class GPSController:
    """A trained GPS policy with its state building.

    Args:
        config: The controllers YAML (default ``configs/controllers.yaml``); its ``reach_time_s``
            becomes the policy's trial length (``config.reach_time_s``).
        policy: The directory ``gazebot gps train --out`` wrote.

    Raises:
        ValueError: no policy directory, a FULL-state policy, or the optional ``gps`` extra is
            missing; ``ConfigError`` for a directory that holds no policy.
    """

    name = GPS

    def __init__(self, config: ControllersConfig | None = None,
                 policy: str | Path | None = None) -> None:
        if policy is None:
            raise ValueError(
                "controller 'gps' runs a learned policy: give its directory "
                "(--policy DIR, written by `gazebot gps train --out DIR`)"
            )
        try:
            from gazebot.apps.gps.policy_store import load
            from gazebot.apps.gps.reach_scene import HandoverScene
            from gazebot.apps.gps.state import StateKind
        except ImportError as exc:
            raise ValueError(
                f"controller 'gps' needs the optional extra: pip install 'gazebot[gps]' ({exc})"
            ) from None
        self.trained = load(policy)
        self.kind = self.trained.kind
        if self.kind is StateKind.FULL:
            raise ValueError(
                f"policy {policy}: state 'full' needs {MISSING_IN_HANDOVER}, which the "
                "handover scene does not have (a person's arm is no 2-DoF tester); "
                "train with --state reduced or relative"
            )
        self.scene_cfg = self.trained.cfg.scene
        # The policy was trained to reach within one trial ("Each trial runs for 2 seconds",
        # seed 5.4): that is its "reach before", what the robot's reach events announce.
        base = config if config is not None else load_controllers_config()
        self.config = base.model_copy(update={"reach_time_s": float(self.scene_cfg.trial_s)})
        self._tester = HandoverScene(self.scene_cfg)  # poses the tester's cylinder (p_o)
        self._tau_max = self._tester.u_bounds[1][:7]
        self._prev: tuple[float, np.ndarray, np.ndarray] | None = None

    @property
    def dt(self) -> float:
        """The policy's control period (s): torques are held this long, as in training."""
        return float(self.scene_cfg.control_dt_s)

    @property
    def tau_max(self) -> np.ndarray:
        """The Panda's joint torque bounds (N m): commands are clipped to +-these."""
        return self._tau_max.copy()

    def reset(self) -> None:
        """Forget the previous hand sample (velocities restart from zero)."""
        self._prev = None

    def _object(self, p_h: np.ndarray) -> np.ndarray:
        """The tester's three cylinder points for its hand at ``p_h`` (base frame)."""
        from gazebot.apps.gps.tester import motion_to

        obs = self._tester.reset(motion_to(p_h, False, self.scene_cfg.tester))
        return obs.p_o + (p_h - obs.p_h)  # exactly at p_h (eq. 5.12 settles 1.6% beyond)

    def state(self, t: float, learner: LearnerState, p_h: np.ndarray) -> np.ndarray:
        """The policy's state x_t at time ``t`` (s) for the learner and the hand ``p_h``.

        Raises:
            ValueError: the tester cannot hold its cylinder at ``p_h`` (out of its reach).
        """
        from gazebot.apps.gps.reach_scene import Observation
        from gazebot.apps.gps.state import state_vector

        p_h = np.asarray(p_h, float)
        p_o = self._object(p_h)
        if self._prev is None or t <= self._prev[0]:
            dp_h, dp_o = np.zeros(3), np.zeros((3, 3))
        else:
            t0, h0, o0 = self._prev
            dp_h, dp_o = (p_h - h0) / (t - t0), (p_o - o0) / (t - t0)
        self._prev = (t, p_h, p_o)
        obs = Observation(
            theta_r=learner.theta_r, dtheta_r=learner.dtheta_r, theta_h=np.zeros(2),
            dtheta_h=np.zeros(2), p_o=p_o, dp_o=dp_o, p_h=p_h, dp_h=dp_h, p_r=learner.p_r,
            dp_r=learner.dp_r, g_r=learner.g_r, r_ee=learner.r_ee, w_ee=learner.w_ee,
            torque=np.zeros(7),
        )
        return state_vector(obs, self.kind)

    def torques(self, x: np.ndarray) -> np.ndarray | None:
        """The policy's joint torques (N m) at state ``x``, clipped to the Panda's bounds;
        None when the network gives a non-finite value (the caller holds its posture)."""
        u = self.trained.policy.mean(np.asarray(x, float))[:7]
        if not np.all(np.isfinite(u)):
            return None
        return np.clip(u, -self._tau_max, self._tau_max)
