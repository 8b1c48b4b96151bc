"""The chapter-5 MuJoCo scene: the Panda learner (torque controlled, with gripper) facing the 2-DoF
tester with its cylindrical hand. Contacts are off: the task is reaching, and the tester's motion
is prescribed (eq. 5.12 or static), so it is played back kinematically.

The learner's own gravity compensation (as the Panda's controller does beneath its torque
interface) is computed for the nominal end-effector mass; a heavier or lighter end effector leaves
the difference for the policy to fight, which is what the seed's mass sweep (Fig. 5.4) probes.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from gazebot.apps.gps import panda
from gazebot.apps.gps.config import SceneConfig
from gazebot.apps.gps.tester import TesterMotion

N_ARM = 7
DU = N_ARM + 1  # seven joint torques and the gripper force


def scene_mjcf(cfg: SceneConfig, ee_mass_kg: float | None = None) -> str:
    """The whole scene as an MJCF string; ``ee_mass_kg`` overrides the end-effector mass."""
    mass = cfg.ee_mass_kg if ee_mass_kg is None else ee_mass_kg
    tc = cfg.tester
    gravcomp_hand = cfg.ee_mass_kg / mass
    return f"""<mujoco model="gps_handover">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{cfg.timestep_s}" integrator="implicitfast">
    <flag contact="disable"/>
  </option>
  <default>
    <default class="learner"><geom rgba="0.92 0.92 0.95 1" contype="0" conaffinity="0"/></default>
    <default class="tester"><geom rgba="0.85 0.6 0.45 1" contype="0" conaffinity="0"/></default>
  </default>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1"/>
    <camera name="side" pos="0.55 -1.9 0.9" xyaxes="1 0 0 0 0.25 1"/>
    <geom type="plane" size="3 3 0.1" rgba="0.3 0.3 0.3 1" contype="0" conaffinity="0"/>
    {panda.panda_mjcf(mass, cfg.joint_damping, gravcomp_hand)}
    <body name="tester_base" gravcomp="1">
      <joint name="tester_azimuth" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="1" diaginertia="0.1 0.1 0.1"/>
      <body name="tester_shoulder" pos="{tc.shoulder_distance_m} 0 {tc.shoulder_height_m}"
            gravcomp="1">
        <joint name="tester_shoulder" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 {-tc.upper_arm_m}" size="0.04" class="tester"/>
        <body name="tester_forearm" pos="0 0 {-tc.upper_arm_m}" gravcomp="1">
          <joint name="tester_elbow" axis="0 1 0"/>
          <geom type="capsule" fromto="0 0 0 0 0 {-tc.forearm_m}" size="0.035" class="tester"/>
          <body name="tester_hand" pos="0 0 {-tc.forearm_m}" gravcomp="1">
            <geom type="cylinder" size="{tc.hand_radius_m} {tc.hand_length_m / 2}"
                  euler="1.5707963 0 0" mass="{tc.hand_mass_kg}" class="tester"/>
            <site name="hand" size="0.01"/>
            <site name="object_a" pos="0 {tc.hand_length_m / 2} 0" size="0.005"/>
            <site name="object_b" pos="0 {-tc.hand_length_m / 2} 0" size="0.005"/>
            <site name="object_c" pos="0 0 {-tc.hand_radius_m}" size="0.005"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon>
    {panda.fingers_tendon()}
  </tendon>
  <actuator>
    {panda.panda_actuators(cfg.gripper_force_n)}
  </actuator>
</mujoco>"""


@dataclass(frozen=True)
class Observation:
    """What the state representations (eqs. 5.8-5.10) are made of, in the learner's base frame."""

    theta_r: np.ndarray  # (7,) rad
    dtheta_r: np.ndarray  # (7,) rad/s
    theta_h: np.ndarray  # (2,) rad, tester shoulder and elbow
    dtheta_h: np.ndarray  # (2,)
    p_o: np.ndarray  # (3, 3) m, three points on the object (the tester's cylinder)
    dp_o: np.ndarray  # (3, 3) m/s
    p_h: np.ndarray  # (3,) tester hand
    dp_h: np.ndarray
    p_r: np.ndarray  # (3,) learner gripper (fingertip centre)
    dp_r: np.ndarray
    g_r: float  # gripper width [m], 0 closed
    r_ee: np.ndarray  # (3, 3) gripper frame orientation
    w_ee: np.ndarray  # (3,) gripper angular velocity, world frame
    torque: np.ndarray  # (7,) N m applied: command + the robot's gravity compensation


class HandoverScene:
    """One simulated trial at a time: :meth:`reset` with a tester motion, then :meth:`step`."""

    def __init__(self, cfg: SceneConfig, ee_mass_kg: float | None = None):
        self.cfg = cfg
        self.model = mujoco.MjModel.from_xml_string(scene_mjcf(cfg, ee_mass_kg))
        self.data = mujoco.MjData(self.model)
        m = self.model
        self._arm_q = np.array([m.jnt_qposadr[m.joint(f"joint{i + 1}").id] for i in range(N_ARM)])
        self._arm_v = np.array([m.jnt_dofadr[m.joint(f"joint{i + 1}").id] for i in range(N_ARM)])
        fingers = [m.joint(f"finger_{s}").id for s in ("left", "right")]
        self._finger_q = np.array([m.jnt_qposadr[j] for j in fingers])
        tester = [m.joint(n).id for n in ("tester_azimuth", "tester_shoulder", "tester_elbow")]
        self._tester_q = np.array([m.jnt_qposadr[j] for j in tester])
        self._tester_v = np.array([m.jnt_dofadr[j] for j in tester])
        self._sites = {n: m.site(n).id for n in ("tcp", "hand", "object_a", "object_b",
                                                 "object_c")}
        self._u_low = m.actuator_ctrlrange[:, 0].copy()
        self._u_high = m.actuator_ctrlrange[:, 1].copy()
        self.motion: TesterMotion | None = None
        self._vel = np.zeros(6)

    @property
    def u_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(u_min, u_max): joint torque [N m] and gripper force [N] limits."""
        return self._u_low.copy(), self._u_high.copy()

    @property
    def time(self) -> float:
        return float(self.data.time)

    def reset(self, motion: TesterMotion) -> Observation:
        """Learner at its home posture with the gripper open, tester at the motion's start."""
        mujoco.mj_resetData(self.model, self.data)
        self.motion = motion
        self.data.qpos[self._arm_q] = self.cfg.home_rad
        self.data.qpos[self._finger_q] = panda.FINGER_RANGE_M[1]
        self._place_tester(0.0)
        mujoco.mj_forward(self.model, self.data)
        return self.observe()

    def _place_tester(self, t: float) -> None:
        assert self.motion is not None
        q, qd = self.motion.joints(t, self.cfg.tester)
        self.data.qpos[self._tester_q] = (self.motion.azimuth, q[0], q[1])
        self.data.qvel[self._tester_v] = (0.0, qd[0], qd[1])

    def clip(self, u: np.ndarray) -> np.ndarray:
        """The command actually applied: within the actuator bounds, and no non-finite value
        (a non-finite entry becomes 0, leaving the robot's gravity compensation alone)."""
        u = np.where(np.isfinite(u), u, 0.0)
        return np.clip(u, self._u_low, self._u_high)

    def step(self, u: np.ndarray) -> Observation:
        """Hold the (clipped) command ``u`` = [7 torques, gripper force] for one control period."""
        self.data.ctrl[:] = self.clip(np.asarray(u, dtype=float))
        for _ in range(self.cfg.substeps):
            self._place_tester(self.data.time)
            mujoco.mj_step(self.model, self.data)
        self._place_tester(self.data.time)
        mujoco.mj_forward(self.model, self.data)
        return self.observe()

    def _site(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        sid = self._sites[name]
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_SITE, sid,
                                 self._vel, 0)
        return self.data.site_xpos[sid].copy(), self._vel.copy()

    def observe(self) -> Observation:
        d = self.data
        p_r, v_r = self._site("tcp")
        p_h, v_h = self._site("hand")
        objs = [self._site(n) for n in ("object_a", "object_b", "object_c")]
        gravcomp = d.qfrc_gravcomp[self._arm_v]
        return Observation(
            theta_r=d.qpos[self._arm_q].copy(),
            dtheta_r=d.qvel[self._arm_v].copy(),
            theta_h=d.qpos[self._tester_q[1:]].copy(),
            dtheta_h=d.qvel[self._tester_v[1:]].copy(),
            p_o=np.array([p for p, _ in objs]),
            dp_o=np.array([v[3:] for _, v in objs]),
            p_h=p_h,
            dp_h=v_h[3:],
            p_r=p_r,
            dp_r=v_r[3:],
            g_r=float(d.qpos[self._finger_q].sum()),
            r_ee=d.site_xmat[self._sites["tcp"]].reshape(3, 3).copy(),
            w_ee=v_r[:3],
            torque=d.ctrl[:N_ARM] + gravcomp,
        )
