"""The robot's reach with the learned GPS policy
(:class:`gazebot.apps.controllers.gps.GPSController`):
every policy control period the learner's state is read from the simulation, expressed in the
arm's base frame, and the policy's joint torques are held until the next period (the zero-order
hold the policy was trained with). It offers the interface the handover controller uses of a
:class:`~gazebot.apps.sim.cartesian_reach.CartesianReach` (``start``, ``update``, ``hold``), and its
steps carry torques instead of joint goals.

A state the policy cannot be given (a hand out of the tester's reach) or a non-finite policy
output holds the posture of that moment instead (joint impedance) and is counted in
:attr:`PolicyReach.fallbacks`, with the first reason in :attr:`PolicyReach.fallback_reason`.
"""

from __future__ import annotations

import mujoco
import numpy as np

from gazebot.apps.controllers.gps import GPSController, LearnerState
from gazebot.apps.sim.cartesian_reach import ReachStep


class PolicyReach:
    """Runs ``controller`` on the arm ``joints`` of ``model``/``data`` (read only).

    Args:
        controller: The loaded policy.
        model: The handover scene's model; ``data`` its state.
        joints: The arm's seven joints, base to wrist.
        gripper_site: The fingertip centre (the policy's ``p_r``).
        fingers: The two finger slide joints (the gripper width ``g_r`` is their sum).

    Raises:
        ValueError: the arm is not the learner the policy was trained on (joint damping or
            end-effector mass differ, or its joints are not torque motors of its bounds).
    """

    def __init__(self, controller: GPSController, model: mujoco.MjModel, data: mujoco.MjData,
                 joints: tuple[str, ...], gripper_site: str,
                 fingers: tuple[str, str] = ("finger_left", "finger_right")) -> None:
        self.controller = controller
        self.model, self.data = model, data
        ids = [model.joint(j).id for j in joints]
        self._qadr = np.array([model.jnt_qposadr[i] for i in ids])
        self._vadr = np.array([model.jnt_dofadr[i] for i in ids])
        self._site = model.site(gripper_site).id
        self._fingers = np.array([model.jnt_qposadr[model.joint(f).id] for f in fingers])
        self._base = int(model.body_parentid[model.jnt_bodyid[ids[0]]])  # link0
        self._check_learner(ids)
        self._vel = np.zeros(6)
        self._t0 = np.nan
        self._next = np.inf
        self._tau = np.zeros(len(joints))
        self._hold_q: np.ndarray | None = None  # set while falling back
        self._q_last = np.zeros(len(joints))
        self.fallbacks = 0
        self.fallback_reason: str | None = None

    def _check_learner(self, ids: list[int]) -> None:
        m, cfg = self.model, self.controller.scene_cfg
        damping = m.dof_damping[self._vadr]
        if not np.allclose(damping, cfg.joint_damping):
            raise ValueError(f"controller 'gps': the arm's joint damping {damping.tolist()} is "
                             f"not the policy's scene.joint_damping {list(cfg.joint_damping)}")
        hand = m.body("hand").id if mujoco.mj_name2id(
            m, mujoco.mjtObj.mjOBJ_BODY, "hand") >= 0 else -1
        if hand < 0 or not np.isclose(m.body_mass[hand], cfg.ee_mass_kg):
            got = None if hand < 0 else float(m.body_mass[hand])
            raise ValueError(f"controller 'gps': the arm's end-effector mass {got} kg is not the "
                             f"policy's scene.ee_mass_kg {cfg.ee_mass_kg}")

    # --------------------------------------------------------------- the CartesianReach interface
    def start(self, t: float, q: np.ndarray) -> None:
        """The handover (and the policy's trial) starts at ``t`` with the arm at ``q``."""
        self.controller.reset()
        self._t0, self._next = float(t), float(t)
        self._q_last = np.asarray(q, float).copy()
        self._hold_q = None

    @property
    def started(self) -> bool:
        return bool(np.isfinite(self._t0))

    def elapsed(self, t: float) -> float:
        return t - self._t0

    def learner(self) -> LearnerState:
        """The learner's measured state in its arm's base frame."""
        m, d = self.model, self.data
        rot = d.xmat[self._base].reshape(3, 3)
        origin = d.xpos[self._base]
        # The simulation steps and then updates positions only (mj_kinematics), so the body
        # velocities are one physics step old: bring them to the current state, as the
        # training scene's mj_forward does before it reads them.
        mujoco.mj_comPos(m, d)
        mujoco.mj_comVel(m, d)
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_SITE, self._site, self._vel, 0)
        return LearnerState(
            theta_r=d.qpos[self._qadr].copy(),
            dtheta_r=d.qvel[self._vadr].copy(),
            p_r=rot.T @ (d.site_xpos[self._site] - origin),
            dp_r=rot.T @ self._vel[3:],
            r_ee=rot.T @ d.site_xmat[self._site].reshape(3, 3),
            w_ee=rot.T @ self._vel[:3],
            g_r=float(d.qpos[self._fingers].sum()),
        )

    def to_base(self, p: np.ndarray) -> np.ndarray:
        """A scene point (m) in the arm's base frame."""
        rot = self.data.xmat[self._base].reshape(3, 3)
        return rot.T @ (np.asarray(p, float) - self.data.xpos[self._base])

    def _fallback(self, reason: str) -> None:
        self.fallbacks += 1
        if self.fallback_reason is None:
            self.fallback_reason = reason
        if self._hold_q is None:
            self._hold_q = self.data.qpos[self._qadr].copy()

    def update(self, t: float, dt: float, hand: np.ndarray, **_ignored: object) -> ReachStep:
        """Advance to ``t`` toward ``hand`` (the reach goal, scene frame): a new policy action
        when a control period has passed. The step's ``torque`` is what the arm applies (None:
        hold ``q`` by impedance)."""
        learner = self.learner()
        self._q_last = learner.theta_r
        if t + 1e-9 >= self._next:
            self._next += self.controller.dt
            while self._next <= t:
                self._next += self.controller.dt
            tau = None
            try:
                x = self.controller.state(self.elapsed(t), learner, self.to_base(hand))
            except ValueError as exc:  # the tester cannot pose its cylinder there
                self._fallback(f"state: {exc}")
            else:
                tau = self.controller.torques(x)
                if tau is None:
                    self._fallback("the policy's torques were not finite")
            if tau is not None:
                self._tau, self._hold_q = tau, None
        rot = self.data.xmat[self._base].reshape(3, 3)
        velocity = rot @ learner.dp_r
        if self._hold_q is not None:
            return ReachStep(q=self._hold_q.copy(), velocity=velocity, plan=None, torque=None)
        return ReachStep(q=learner.theta_r, velocity=velocity, plan=None,
                         torque=self._tau.copy())

    def hold(self) -> np.ndarray:
        """The joints to hold once the reach is over: the posture it ended in."""
        return (self._hold_q if self._hold_q is not None else self._q_last).copy()


class PolicyReachLog:
    """What a learned reach did over a run (pass :meth:`on_tick` as ``record_handover``'s
    ``on_tick``): the gripper's distance to the reach goal (the object in the giver's hand) and
    to the giver's hand when the reach started and when it ended (the grasp distance reached, or
    the run's end), the largest arm torque applied, and the fallbacks."""

    def __init__(self) -> None:
        self._start: tuple[float, float] | None = None
        self._end: tuple[float, float] | None = None
        self._reach_s = 0.0
        self._t0: float | None = None
        self.max_torque_nm = 0.0
        self._reach: PolicyReach | None = None

    def on_tick(self, sim, _tick=None) -> None:
        from gazebot.apps.sim.arm_controller import ControllerState

        reach = sim.controller.reach
        if not isinstance(reach, PolicyReach):
            return
        self._reach = reach
        if sim.controller.state not in (ControllerState.REACHING, ControllerState.AT_HANDOVER):
            return
        # the policy's own torques (home, retreat and holding run the impedance law)
        self.max_torque_nm = max(self.max_torque_nm,
                                 float(np.abs(sim.data.ctrl[sim._arm_act]).max()))
        gripper = sim.data.site_xpos[sim._gripper_site]
        gaps = (float(np.linalg.norm(gripper - sim.data.mocap_pos[sim.scene.object_mocap])),
                float(np.linalg.norm(gripper - sim.giver.hand)))
        if self._start is None:
            self._start, self._t0 = gaps, sim.t
        self._end, self._reach_s = gaps, sim.t - self._t0

    def summary(self) -> dict | None:
        """The JSON summary (m, s, N m), None when no learned reach ran."""
        if self._reach is None:
            return None
        r = self._reach
        gaps = {}
        for key, value in (("start", self._start), ("end", self._end)):
            gaps[f"object_gap_{key}_m"] = None if value is None else round(value[0], 4)
            gaps[f"hand_gap_{key}_m"] = None if value is None else round(value[1], 4)
        return {
            "policy_state": r.controller.kind.value,
            **gaps,
            "reach_s": round(self._reach_s, 3),
            "max_torque_nm": round(self.max_torque_nm, 3),
            "fallbacks": r.fallbacks,
            "fallback_reason": r.fallback_reason,
        }
