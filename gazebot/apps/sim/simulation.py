"""``HandoverSimulation``: a human-to-robot handover in MuJoCo (seed sections 6.3.2 and 6.4.3).

A simulated giver reaches toward the robot with the object; the robot's handover controller reaches
a predefined handover pose once the giver starts, grasps when the object is close and retreats home
after the giver lets go. The gaze engine (or a bus node) reads :meth:`tracking` and
:meth:`robot_events` and drives the head (:meth:`apply_head`) and the eyes on the head display
(:meth:`apply_eyes` / :meth:`set_display`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from gazebot.apps.controllers.base import INFEASIBLE_MESSAGE
from gazebot.apps.render.offscreen import OffscreenRenderer
from gazebot.apps.render.video_settings import VIDEO
from gazebot.apps.sim.arm_controller import ControllerState, HandoverController, Sensed
from gazebot.apps.sim.cartesian_reach import CartesianReach
from gazebot.apps.sim.display_texture import DisplayTexture
from gazebot.apps.sim.giver import GiverPlan, GiverState, SimulatedGiver
from gazebot.apps.sim.receiver import ReceiverState, SimulatedReceiver
from gazebot.apps.sim.robot import SimRobot, load_sim_robot
from gazebot.apps.sim.scene import OBSERVER, Scene, build_scene
from gazebot.apps.sim.scene_config import (
    GPS_REACH,
    JOINT_REACH,
    ControllerConfig,
    Direction,
    Initiator,
    InsetConfig,
    RetreatTrigger,
    SceneConfig,
    TrackingNoiseConfig,
    load_scene,
)
from gazebot.apps.sim.torque_arm import (
    JointImpedance,
    arm_actuator,
    impedance_from_model,
    is_torque_motor,
)
from gazebot.apps.sim.tracking import TrackingNoise
from gazebot.core.defaults import DEFAULT_ROBOT
from gazebot.core.kinematics.robot_config import RobotConfig
from gazebot.core.types import Event, EventKind, TrackingFrame

if TYPE_CHECKING:
    from gazebot.apps.sim.policy_reach import PolicyReach


def _feedback_banner(frame: np.ndarray, text: str) -> np.ndarray:
    """``frame`` with the robot's failure feedback (seed 3.2) in a banner along the top."""
    import cv2

    out = np.ascontiguousarray(frame).copy()
    h, w = out.shape[:2]
    scale = max(0.35, w / 1400.0)
    (tw, th), base = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, scale, 1)
    bar = th + base + 12
    out[:bar] = (out[:bar] * 0.35 + np.array([150, 20, 20]) * 0.65).astype(np.uint8)
    cv2.putText(
        out,
        text,
        (max(4, (w - tw) // 2), th + 6),
        cv2.FONT_HERSHEY_SIMPLEX,
        scale,
        (255, 255, 255),
        1,
        cv2.LINE_AA,
    )
    return out


def inset_rect(
    width: int, height: int, screen: tuple[int, int], inset: InsetConfig
) -> tuple[int, int, int, int]:
    """Where the screen close-up goes in a ``width`` x ``height`` frame: (x0, y0, x1, y1) px, the
    screen's aspect kept (``screen`` = its texture's (width, height))."""
    w = max(8, round(inset.width_frac * width))
    h = max(4, round(w * screen[1] / screen[0]))
    pad = max(2, round(width / 80))
    x0 = pad if "left" in inset.corner.value else width - pad - w
    y0 = pad if "top" in inset.corner.value else height - pad - h
    return x0, y0, x0 + w, y0 + h


def _paste_inset(frame: np.ndarray, screen: np.ndarray, rect: tuple[int, int, int, int]) -> None:
    """Draw ``screen`` (the head display's texture, RGB) into ``rect`` of ``frame``, framed by a
    thin light border so it reads as a picture-in-picture."""
    import cv2

    x0, y0, x1, y1 = rect
    border = max(1, (x1 - x0) // 90)
    frame[y0:y1, x0:x1] = (235, 235, 235)
    inner = (x1 - x0 - 2 * border, y1 - y0 - 2 * border)
    frame[y0 + border : y1 - border, x0 + border : x1 - border] = cv2.resize(
        screen, inner, interpolation=cv2.INTER_AREA
    )


def nearest_equivalent(q: np.ndarray, goal: np.ndarray, ranges: np.ndarray) -> np.ndarray:
    """``q`` with each joint shifted by whole turns (staying within its range) to be as close as
    possible to ``goal``: the same arm configuration, but no needless full-turn moves on joints
    that turn more than 360 deg (e.g. the Jaco-2's)."""
    out = np.asarray(q, float).copy()
    for i, (lo, hi) in enumerate(ranges):
        if hi - lo < 2 * np.pi:
            continue
        shifted = out[i] + 2 * np.pi * np.arange(-2, 3)
        ok = shifted[(shifted >= lo) & (shifted <= hi)]
        if ok.size:
            out[i] = ok[np.argmin(np.abs(ok - goal[i]))]
    return out


class HandoverSimulation:
    """One simulated handover.

    Args:
        robot: Robot name (``sawyer``, ``jaco2``, ``panda``: a torque-motor arm whose position
            goals go through joint impedance, :mod:`gazebot.apps.sim.torque_arm`), robot YAML path,
            parsed :class:`~gazebot.core.kinematics.RobotConfig` or a :class:`SimRobot`.
        scene: Scene name (``configs/scenes/<name>.yaml``), YAML path or a :class:`SceneConfig`.
        seed: Seeds the giver's timing and the tracking noise (same seed, same handover).
        tracking_noise: Overrides the scene's tracking noise (``None``: the scene's).
        giver_factory: Builds the person instead of the simulated one, called as
            ``(rest, offer, plan, cued)`` (e.g. :func:`gazebot.apps.sim.giver_replay.replay_factory`
            for recorded motion); ``None``: the scene's ``giver_motion`` if it has one (study
            scenes), else the simulated giver.
    """

    def __init__(
        self,
        robot: str | Path | RobotConfig | SimRobot = DEFAULT_ROBOT,
        scene: str | Path | SceneConfig = "default",
        seed: int = 0,
        tracking_noise: TrackingNoiseConfig | None = None,
        giver_factory=None,
    ) -> None:
        self.robot = robot if isinstance(robot, SimRobot) else load_sim_robot(robot)
        self.config = load_scene(scene)
        self.seed = int(seed)
        self.scene: Scene = build_scene(self.robot, self.config)
        self.model = self.scene.model
        self.data = mujoco.MjData(self.model)
        self.layout = self.scene.layout

        m = self.model
        self._arm_qpos = np.array([m.joint(j).qposadr[0] for j in self.robot.arm_joints])
        self._arm_act = np.array([self._arm_actuator(j) for j in self.robot.arm_joints])
        self._arm_qvel = np.array([m.joint(j).dofadr[0] for j in self.robot.arm_joints])
        # A torque-motor arm (the Panda learner) takes position goals through joint impedance.
        self._impedance: JointImpedance | None = None
        if all(is_torque_motor(m, a) for a in self._arm_act):
            self._impedance = impedance_from_model(m, self._arm_act, self.robot.mjcf)
        self._head_act = {j: self._actuator(j) for j in self.robot.head_joints}
        self._head_qpos = {j: int(m.joint(j).qposadr[0]) for j in self.robot.head_joints}
        self._gripper_act = self._actuator(self.robot.gripper_actuator)
        self._gripper_site = int(m.site(self.robot.gripper_site).id)
        self._joint_names = [
            m.joint(i).name
            for i in range(m.njnt)
            if int(m.jnt_type[i])
            in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
        ]

        self._arm_lo, self._arm_hi = np.array([self._ctrl_limits(a) for a in self._arm_act]).T
        if self._impedance is not None:  # goals are bounded by the joints, not the motors
            joint_ids = [m.joint(j).id for j in self.robot.arm_joints]
            self._arm_lo, self._arm_hi = m.jnt_range[joint_ids].T
        arm_ranges = np.array([m.jnt_range[m.joint(j).id] for j in self.robot.arm_joints])
        self.home = nearest_equivalent(self.robot.home, self.robot.handover, arm_ranges)
        self.data.qpos[self._arm_qpos] = self.home
        self._arm_goal = self.home.copy()
        if self._impedance is None:
            self.data.ctrl[self._arm_act] = self.home
        for j, a in self._head_act.items():
            self.data.ctrl[a] = self._clip_ctrl(a, self.data.qpos[self._head_qpos[j]])
        self.data.ctrl[self._gripper_act] = 0.0

        rng = np.random.default_rng([self.seed, 0])
        plan = GiverPlan.draw(self.config.giver, rng)
        self.robot_initiated = self.config.initiator is Initiator.ROBOT
        self.robot_to_human = self.config.direction is Direction.ROBOT_TO_HUMAN
        # A robot-initiated giver waits for the robot's reach (respond_at) plus a reaction time.
        # ``giver`` is the simulated person: in a robot-to-human scene, the one who takes it.
        human = SimulatedReceiver if self.robot_to_human else SimulatedGiver
        if giver_factory is None and self.config.giver_motion is not None:
            from gazebot.apps.sim.giver_replay import load_giver_motion

            gm = self.config.giver_motion
            giver_factory = load_giver_motion(
                gm.file, gm.giver_hand, gm.receiver_hand, gm.giver_face, gm.unit, gm.rate_hz
            )
        if giver_factory is not None:
            human = giver_factory  # e.g. a recorded giver (gazebot.apps.sim.giver_replay)
        self.giver = human(
            self.layout.rest_hand, self.layout.offer_hand, plan, cued=self.robot_initiated
        )
        ctrl = self.config.controller
        self._reach_for_gripper = self._cartesian_reach(ctrl)
        self.controller = HandoverController(
            self.home,
            self.robot.handover,
            ctrl,
            reach=self._reach_for_gripper,
            start_at=ctrl.robot_start_s if self.robot_initiated else None,
            target=np.asarray(self.robot.config.points["handover_location"], float)
            if "handover_location" in self.robot.config.points
            else None,
            giver=self.robot_to_human,
            **self._whole_task(ctrl),
        )
        self.data.ctrl[self._gripper_act] = self._clip_ctrl(
            self._gripper_act, self.controller._gripper
        )
        self._noise = TrackingNoise(
            tracking_noise or self.config.tracking, np.random.default_rng([self.seed, 1])
        )
        self.display = DisplayTexture(m)
        self._eyes: tuple[float, float, float, float | None] | None = None
        self._eyes_drawn: tuple | None = None
        self._eye_renderer = None
        self._renderers: dict[tuple[int, int], OffscreenRenderer] = {}
        self._events: list[Event] = []
        self._object_rel: tuple[np.ndarray, np.ndarray] | None = None  # object in gripper frame
        self._object_in_hand: np.ndarray | None = None  # robot-to-human: object minus hand
        self._arm_external = False
        self._t = 0.0
        mujoco.mj_kinematics(m, self.data)  # the gripper's pose, for an object it starts holding
        self._place_kinematic()
        mujoco.mj_forward(m, self.data)

    # ----------------------------------------------------------------------------- helpers
    def _cartesian_reach(self, ctrl: ControllerConfig) -> CartesianReach | PolicyReach | None:
        """The seed's reach controller on the arm (the learned ``gps`` policy's torque-level
        reach on a torque arm), or None for the joint-space reach."""
        if ctrl.reach_controller == JOINT_REACH:
            return None
        if ctrl.reach_controller == GPS_REACH:
            return self._policy_reach(ctrl)
        from gazebot.apps.controllers import make_controller
        from gazebot.apps.controllers.arm_ik import ArmIK
        from gazebot.apps.sim.cartesian_reach import scene_controllers_config

        cfg = scene_controllers_config(ctrl, self.config.direction is Direction.ROBOT_TO_HUMAN)
        m = self.model
        ranges = np.array([m.jnt_range[m.joint(j).id] for j in self.robot.arm_joints])
        ik = ArmIK(
            self.robot.mjcf,
            self.robot.arm_joints,
            self.robot.gripper_site,
            max_joint_speed=np.deg2rad(ctrl.max_joint_speed_deg),
            lower=np.maximum(ranges[:, 0], self._arm_lo),
            upper=np.minimum(ranges[:, 1], self._arm_hi),
        )
        # The STL handover zone is centred on the robot's base: the first arm joint's body.
        mujoco.mj_kinematics(m, self.data)
        base = self.data.xpos[m.jnt_bodyid[m.joint(self.robot.arm_joints[0]).id]].copy()
        return CartesianReach(make_controller(ctrl.reach_controller, cfg), ik, base)

    def _policy_reach(self, ctrl: ControllerConfig) -> PolicyReach:
        """The ``gps`` policy of ``ctrl.policy`` on this robot's arm.

        Raises:
            ValueError: the robot's arm is not a torque-controlled Panda learner, or the policy
                cannot run here (see :class:`~gazebot.apps.controllers.gps.GPSController`).
        """
        from gazebot.apps.controllers import CONTROLLERS
        from gazebot.apps.controllers.config import load_controllers_config
        from gazebot.apps.sim.policy_reach import PolicyReach

        if self._impedance is None or len(self.robot.arm_joints) != 7:
            raise ValueError(
                f"controller 'gps' drives the Panda learner's seven joint torques: robot "
                f"{self.robot.name!r} has no torque-controlled 7-joint arm (use --robot panda)"
            )
        policy = CONTROLLERS.make(GPS_REACH, load_controllers_config(ctrl.controllers),
                                  policy=ctrl.policy)
        mujoco.mj_kinematics(self.model, self.data)
        return PolicyReach(policy, self.model, self.data, self.robot.arm_joints,
                           self.robot.gripper_site)

    def _whole_task(self, ctrl: ControllerConfig) -> dict:
        """The pick-up / drop-off of Table 4.2's whole task, with the STL gripper (scene
        validation makes sure the reach is ``stl``)."""
        if ctrl.pickup_m is None and ctrl.dropoff_m is None:
            return {}
        from gazebot.apps.controllers.stl_gripper import STLGripper

        reach = self._reach_for_gripper
        assert reach is not None
        timing = reach.controller.config
        return {
            "pickup": None if ctrl.pickup_m is None else np.asarray(ctrl.pickup_m, float),
            "dropoff": None if ctrl.dropoff_m is None else np.asarray(ctrl.dropoff_m, float),
            "gripper": STLGripper(timing.stl, timing.dt_s),
        }

    def _arm_actuator(self, joint: str) -> int:
        act = arm_actuator(self.model, joint)
        if act < 0:
            raise ValueError(f"robot {self.robot.name!r} has no actuator on arm joint {joint!r}")
        return act

    def _actuator(self, name: str) -> int:
        act = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        if act < 0:
            raise ValueError(f"robot {self.robot.name!r} has no position actuator named {name!r}")
        return act

    def _ctrl_limits(self, act: int) -> tuple[float, float]:
        """The actuator's control range, else its joint's range, else unbounded."""
        m = self.model
        if m.actuator_ctrllimited[act]:
            lo, hi = m.actuator_ctrlrange[act]
        elif m.jnt_limited[m.actuator_trnid[act, 0]]:
            lo, hi = m.jnt_range[m.actuator_trnid[act, 0]]
        else:
            lo, hi = -np.inf, np.inf
        return float(lo), float(hi)

    def _clip_ctrl(self, act: int, value: float) -> float:
        lo, hi = self._ctrl_limits(act)
        return min(max(float(value), lo), hi)

    def _gripper_pose(self) -> tuple[np.ndarray, np.ndarray]:
        pos = self.data.site_xpos[self._gripper_site].copy()
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, self.data.site_xmat[self._gripper_site])
        return pos, quat

    def _place_kinematic(self) -> None:
        """Pose the giver's arm and the object for the current state."""
        hand = self.giver.hand
        self.scene.giver.pose_arm(self.data, hand)
        mocap = self.scene.object_mocap
        if self.robot_to_human:
            self._place_object_robot_giver(hand)
            return
        if self.controller.dropped:
            return  # left at the drop-off
        if self.giver.holds_object or not self.controller.grasped:
            self.data.mocap_pos[mocap] = hand + self.layout.object_offset
            self.data.mocap_quat[mocap] = [1.0, 0.0, 0.0, 0.0]
            return
        g_pos, g_quat = self._gripper_pose()
        if self._object_rel is None:
            # The giver just let go: from now on the object moves with the gripper.
            inv = np.zeros(4)
            mujoco.mju_negQuat(inv, g_quat)
            rel_pos = np.zeros(3)
            mujoco.mju_rotVecQuat(rel_pos, self.data.mocap_pos[mocap] - g_pos, inv)
            rel_quat = np.zeros(4)
            mujoco.mju_mulQuat(rel_quat, inv, self.data.mocap_quat[mocap].copy())
            self._object_rel = (rel_pos, rel_quat)
        self._carry_in_gripper(mocap, g_pos, g_quat)

    def _carry_in_gripper(self, mocap: int, g_pos: np.ndarray, g_quat: np.ndarray) -> None:
        """Pose the object where it was taken in the gripper (``_object_rel``), the gripper at
        ``g_pos``, ``g_quat``."""
        rel_pos, rel_quat = self._object_rel
        world = np.zeros(3)
        mujoco.mju_rotVecQuat(world, rel_pos, g_quat)
        self.data.mocap_pos[mocap] = g_pos + world
        quat = np.zeros(4)
        mujoco.mju_mulQuat(quat, g_quat, rel_quat)
        self.data.mocap_quat[mocap] = quat

    def _place_object_robot_giver(self, hand: np.ndarray) -> None:
        """Robot-to-human: the object rides in the gripper until the robot lets go, then in the
        person's hand (keeping where it was in the hand when taken)."""
        mocap = self.scene.object_mocap
        if self.controller.picking_up:  # on the table at the pick-up, upright
            self.data.mocap_pos[mocap] = self.controller.pickup
            self.data.mocap_quat[mocap] = [1.0, 0.0, 0.0, 0.0]
            return
        if not self.controller.grasped:
            if self._object_in_hand is None:
                self._object_in_hand = self.data.mocap_pos[mocap] - hand
            self.data.mocap_pos[mocap] = hand + self._object_in_hand
            return
        g_pos, g_quat = self._gripper_pose()
        if self._object_rel is None:  # the start (or the pick-up): in the gripper, upright
            inv = np.zeros(4)
            mujoco.mju_negQuat(inv, g_quat)
            rel_quat = np.zeros(4)
            mujoco.mju_mulQuat(rel_quat, inv, np.array([1.0, 0.0, 0.0, 0.0]))
            rel_pos = np.zeros(3)
            if self.controller.pickup is not None:  # it stays where the gripper closed on it
                mujoco.mju_rotVecQuat(rel_pos, self.data.mocap_pos[mocap] - g_pos, inv)
            self._object_rel = (rel_pos, rel_quat)
        self._carry_in_gripper(mocap, g_pos, g_quat)

    # ----------------------------------------------------------------------------- state
    @property
    def t(self) -> float:
        """Simulation time (s) since the start."""
        return self._t

    @property
    def done(self) -> bool:
        """True once the robot is back home with the object and the giver has retreated, or
        once the robot has stopped after finding its reach infeasible (it has said so: the
        failure feedback is on its frames; nothing more will happen)."""
        if self.controller.gave_up(self._t):
            return True
        human_done = self.giver.state in (GiverState.DONE, ReceiverState.DONE)
        return self.controller.state is ControllerState.DONE and human_done

    @property
    def head_joints(self) -> tuple[str, ...]:
        return self.robot.head_joints

    def step(self, dt: float) -> None:
        """Advance the giver, the handover controller and the physics by ``dt`` seconds."""
        if not (math.isfinite(dt) and dt > 0.0):
            raise ValueError(f"step dt must be a positive number of seconds, got {dt}")
        t = self._t + dt
        obj = self.data.mocap_pos[self.scene.object_mocap]
        gripper = self.data.site_xpos[self._gripper_site]
        if self.robot_to_human:
            sensed = self._sense_robot_giver(t, obj)
        else:
            self.giver.update(t, self.controller.grasped)
            sensed = self._sense_robot_receiver(obj, gripper)
        cmd = self.controller.update(t, self.data.qpos[self._arm_qpos], sensed)
        events = self.controller.pop_events()
        for e in events:
            self._on_robot_event(e)
        self._events.extend(events)
        torque = None
        if not self._arm_external:
            # Joint goals inside the arm's ranges, as the position servos get them (NaN stays:
            # it means "hold").
            self._arm_goal = np.clip(np.asarray(cmd.arm, float), self._arm_lo, self._arm_hi)
            torque = cmd.torque
        self.data.ctrl[self._gripper_act] = self._clip_ctrl(self._gripper_act, cmd.gripper)
        n = max(1, round((t - self.data.time) / self.model.opt.timestep))
        if self._impedance is None:
            if not self._arm_external:
                self.data.ctrl[self._arm_act] = np.clip(cmd.arm, self._arm_lo, self._arm_hi)
            mujoco.mj_step(self.model, self.data, nstep=n)
        else:
            self._step_torque_arm(n, torque)
        self._t = t
        mujoco.mj_kinematics(self.model, self.data)
        self._place_kinematic()
        mujoco.mj_kinematics(self.model, self.data)

    def _step_torque_arm(self, n: int, torque: np.ndarray | None) -> None:
        """``n`` physics steps of a torque-motor arm: ``torque`` held (a torque-level reach),
        else the joint impedance toward the arm goal evaluated every step. Never a non-finite
        or out-of-bounds torque."""
        imp = self._impedance
        assert imp is not None
        held = None
        if torque is not None:
            held = np.clip(np.asarray(torque, float), -imp.tau_max, imp.tau_max)
            if not np.all(np.isfinite(held)):
                held = None  # hold the posture instead
                self._arm_goal = self.data.qpos[self._arm_qpos].copy()
        for _ in range(n):
            if held is not None:
                self.data.ctrl[self._arm_act] = held
            else:
                self.data.ctrl[self._arm_act] = imp.torque(
                    self._arm_goal, self.data.qpos[self._arm_qpos], self.data.qvel[self._arm_qvel]
                )
            mujoco.mj_step(self.model, self.data)

    def _sense_robot_giver(self, t: float, obj: np.ndarray) -> Sensed:
        """Robot-to-human: the person takes the object once it is within grasp, the robot lets
        go once the person's hand is at it; ``object_pos`` is where the object goes (in the
        hand), ``object_gap`` how far it still is."""
        into_hand = self.giver.hand + self.layout.object_offset
        gap = float(np.linalg.norm(obj - into_hand))
        released = not self.controller.grasped
        self.giver.update(t, gap <= self.config.controller.grasp_distance_m, released)
        into_hand = self.giver.hand + self.layout.object_offset
        return Sensed(
            giver_hand=self.giver.hand.copy(),
            object_gap=float(np.linalg.norm(obj - into_hand)),
            hand_object_gap=0.0,
            object_pos=into_hand,
        )

    @property
    def robot_load_share(self) -> float:
        """The robot's share of the object's weight, ``alpha_r`` (seed 4.3): 0 while it does not
        grip it, 0.5 while the person grips it too, 1 alone."""
        if not self.controller.grasped:
            return 0.0
        return 0.5 if self.giver.holds_object else 1.0

    def _sense_robot_receiver(self, obj: np.ndarray, gripper: np.ndarray) -> Sensed:
        return Sensed(
            load_share=self.robot_load_share,
            giver_hand=self.giver.hand.copy(),
            object_gap=float(np.linalg.norm(obj - gripper)),
            hand_object_gap=float(
                np.linalg.norm(self.giver.hand + self.layout.object_offset - obj)
            ),
            object_pos=obj.copy(),
        )

    def _on_robot_event(self, event: Event) -> None:
        """The giver's side of the robot's events (methods a replayed giver may lack)."""
        if event.kind is EventKind.ROBOT_REACH_STARTED and self.robot_initiated:
            respond = getattr(self.giver, "respond_at", None)
            if respond is not None:
                respond(event.t + self.config.giver.reaction_time_s)
        if (
            event.kind is EventKind.ROBOT_RETREAT_STARTED
            and self.config.controller.retreat is RetreatTrigger.AFTER_GRASP
        ):
            let_go = getattr(self.giver, "let_go", None)
            if let_go is not None:
                let_go(event.t)

    @property
    def reach_start_time(self) -> float | None:
        """The seed's reach-start time (6.4: "the difference between the start of the human
        hand's reaching motion and the start of the robot arm's reaching motion"): the giver's
        reach start minus the robot's (s; positive when the robot started first), None until
        both have started."""
        giver = getattr(self.giver, "reach_started_at", None)
        robot = self.controller.reach_started_at
        if giver is None or robot is None:
            return None
        return float(giver - robot)

    def tracking(self) -> TrackingFrame:
        """What a motion-capture system would report now (robot base frame, m): the person's
        hand and face, the gripper, and the object's taker's grip and load share (the robot's in
        a human-to-robot scene, the person's in a robot-to-human one)."""
        noise = self._noise.apply
        grasped = self.controller.grasped
        if self.robot_to_human:
            # The person is in the giver_* fields (the robot looks at their face and hand), and
            # the grip and load share are the taker's (the person's), so the phase detector sees
            # the usual sequence: reach, transfer while both hold, retreat once the robot let go.
            takes = self.giver.holds_object
            share = 0.0 if not takes else (0.5 if grasped else 1.0)
            grasped = takes
        elif not grasped:
            share = 0.0
        elif self.giver.holds_object:
            share = 0.5
        else:
            share = 1.0
        return TrackingFrame.make(
            self._t,
            giver_hand=noise(self.giver.hand),
            receiver_hand=noise(self.data.site_xpos[self._gripper_site]),
            giver_face=noise(self.face_point),
            gripper_closed=grasped,
            load_share=share,
        )

    @property
    def face_point(self) -> np.ndarray:
        """The person's face (m, base frame): the scene's, moved by a replayed giver's recorded
        head motion (``face_offset``) when there is one."""
        offset = getattr(self.giver, "face_offset", None)
        face = self.scene.giver.face_point
        return face if offset is None else face + np.asarray(offset, float)

    def joint_state(self) -> dict[str, float]:
        """Every hinge/slide joint's position (rad or m) by name."""
        return {
            name: float(self.data.qpos[self.model.joint(name).qposadr[0]])
            for name in self._joint_names
        }

    def robot_events(self) -> list[Event]:
        """Robot controller events since the last call, oldest first."""
        out, self._events = self._events, []
        return out

    # ----------------------------------------------------------------------------- commands
    def apply_head(self, joints: Mapping[str, float]) -> None:
        """Set head joint goals (rad); values are clipped to the joint limits.

        Raises:
            ValueError: an unknown head joint or a non-finite value.
        """
        for name, value in joints.items():
            if name not in self._head_act:
                raise ValueError(
                    f"unknown head joint {name!r} (head joints: {list(self._head_act)})"
                )
            if not math.isfinite(value):
                raise ValueError(f"head joint {name!r} goal must be finite, got {value}")
        for name, value in joints.items():
            act = self._head_act[name]
            self.data.ctrl[act] = self._clip_ctrl(act, float(value))

    def apply_arm(self, joints: Mapping[str, float]) -> None:
        """Take the arm over from the handover controller and set arm joint goals (rad, clipped).
        The controller keeps running (events, gripper) but no longer moves the arm."""
        arm = dict(zip(self.robot.arm_joints, self._arm_act, strict=True))
        for name, value in joints.items():
            if name not in arm:
                raise ValueError(f"unknown arm joint {name!r} (arm joints: {list(arm)})")
            if not math.isfinite(value):
                raise ValueError(f"arm joint {name!r} goal must be finite, got {value}")
        self._arm_external = True
        if self._impedance is not None:  # goals for the joint impedance, within joint ranges
            index = {j: i for i, j in enumerate(self.robot.arm_joints)}
            for name, value in joints.items():
                jr = self.model.jnt_range[self.model.joint(name).id]
                self._arm_goal[index[name]] = min(max(float(value), jr[0]), jr[1])
            return
        for name, value in joints.items():
            self.data.ctrl[arm[name]] = self._clip_ctrl(arm[name], float(value))

    def release_arm(self) -> None:
        """Hand the arm back to the handover controller after :meth:`apply_arm`."""
        self._arm_external = False

    def apply_eyes(
        self, yaw: float, pitch: float, blink: float = 0.0, distance: float | None = None
    ) -> None:
        """Show eyes looking at (``yaw``, ``pitch``) rad (+yaw = robot's left, +pitch = down) with
        lids ``blink`` (0 open .. 1 closed) on the head display, drawn by the robot's eye renderer
        (``gazebot.apps.render.EyeRenderer``). Drawn lazily, at the next :meth:`render`."""
        values = (yaw, pitch, blink) + ((distance,) if distance is not None else ())
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"eye yaw/pitch/blink/distance must be finite, got {values}")
        self._eyes = (float(yaw), float(pitch), float(np.clip(blink, 0.0, 1.0)), distance)

    @property
    def eyes(self) -> tuple[float, float, float, float | None] | None:
        """The last :meth:`apply_eyes` command (yaw rad, pitch rad, blink, vergence distance m or
        None), or None while the display shows an image from :meth:`set_display` or nothing."""
        return self._eyes

    def set_display(self, image: np.ndarray) -> None:
        """Show ``image`` ((H, W, 3) uint8 RGB) on the head display (replaces the eyes)."""
        self.display.write(image)
        self._eyes = None
        self._eyes_drawn = None

    def _draw_eyes(self) -> None:
        if self._eyes is None or self._eyes == self._eyes_drawn:
            return
        if self._eye_renderer is None:
            from gazebot.apps.render import EyeRenderer

            # The robot's own config (not a lookup by name: a custom robot YAML has no entry
            # anywhere else); drawn at the texture's size, so no resize per frame.
            self._eye_renderer = EyeRenderer.for_robot(
                self.robot.config, width=self.display.width, height=self.display.height
            )
        yaw, pitch, blink, distance = self._eyes
        self.display.write(self._eye_renderer.render(yaw, pitch, blink=blink, distance=distance))
        self._eyes_drawn = self._eyes

    # ----------------------------------------------------------------------------- rendering
    def render(
        self,
        camera: str = OBSERVER,
        width: int = VIDEO.width,
        height: int = VIDEO.height,
        inset: bool | None = None,
    ) -> np.ndarray:
        """An RGB frame ((height, width, 3) uint8) from ``camera`` (default: the observer).

        The observer's frames carry a close-up of the head screen (the display texture as the
        eyes are drawn) in a corner when ``inset`` is True, or when it is None and the scene's
        ``camera.inset.enabled`` is (the default)."""
        self._draw_eyes()
        key = (int(width), int(height))
        renderer = self._renderers.get(key)
        if renderer is None:
            renderer = self._renderers[key] = OffscreenRenderer(self.model, *key)
        if renderer.texture_version.get(self.display.id) != self.display.version:
            renderer.make_current()
            self.display.upload(renderer.context)
            renderer.texture_version[self.display.id] = self.display.version
        frame = renderer.render(self.data, camera)
        if camera == OBSERVER:
            cfg = self.config.camera.inset
            if cfg.enabled if inset is None else inset:
                frame = np.ascontiguousarray(frame)
                _paste_inset(frame, self.display.read(), self.inset_rect(width, height))
            if self.controller.infeasible_at is not None:
                frame = _feedback_banner(frame, INFEASIBLE_MESSAGE)
        return frame

    def inset_rect(
        self, width: int = VIDEO.width, height: int = VIDEO.height
    ) -> tuple[int, int, int, int]:
        """The screen close-up's place (x0, y0, x1, y1) px in an observer frame of that size."""
        return inset_rect(
            width, height, (self.display.width, self.display.height), self.config.camera.inset
        )

    def close(self) -> None:
        """Free the GL contexts (also done when the object is garbage collected)."""
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers.clear()

    def __enter__(self) -> HandoverSimulation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
