"""The robot's reach in the simulator with one of the seed's controllers
(``gazebot.apps.controllers``):
the controller plans an end-effector velocity every control period (``dt_s``); between plans the
velocity is held and the arm tracks the moving set point with differential IK (``ArmIK``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gazebot.apps.controllers import ReachController, ReachObservation, VelocityPlan
from gazebot.apps.controllers.arm_ik import ArmIK
from gazebot.apps.controllers.config import ControllersConfig
from gazebot.apps.sim.scene_config import ControllerConfig


def scene_controllers_config(ctrl: ControllerConfig, robot_gives: bool) -> ControllersConfig:
    """What a scene's Cartesian reach works to: the controllers YAML (``ctrl.controllers``, else
    ``configs/controllers.yaml``) with the scene's reach and stall times, and Table 4.3's giver
    rows for STL when the robot gives (``robot_gives``).

    Raises ``ValueError`` naming the field when the scene's times and the YAML's do not fit
    together (e.g. a stall no shorter than the reach)."""
    from gazebot.apps.controllers import load_controllers_config

    cfg = load_controllers_config(ctrl.controllers)
    update: dict = {}
    if robot_gives:
        update["stl"] = {**cfg.stl.model_dump(), "role": "giver"}
    if ctrl.reach_time_s is not None:
        update["reach_time_s"] = ctrl.reach_time_s
    if ctrl.stall_time_s is not None:
        update["stall_time_s"] = ctrl.stall_time_s
    if not update:
        return cfg
    return type(cfg).model_validate({**cfg.model_dump(), **update})


@dataclass(frozen=True)
class ReachStep:
    """One tick of a reach: arm joint goals and what the plan said; a torque-level reach (the
    learned ``gps`` policy) also gives the joint torques to apply instead of going to ``q``."""

    q: np.ndarray
    velocity: np.ndarray
    plan: VelocityPlan | None  # the plan made this tick, None between plans
    torque: np.ndarray | None = None  # N m, the arm's motors apply these (None: go to q)


class CartesianReach:
    """Tracks a :class:`ReachController`'s plans on the arm.

    Args:
        controller: The reach controller (its ``dt`` is the planning period).
        ik: Differential IK of the arm.
        zone_center: The robot's base (STL handover zone centre), base frame m.
    """

    def __init__(self, controller: ReachController, ik: ArmIK, zone_center: np.ndarray) -> None:
        self.controller = controller
        self.ik = ik
        self.zone_center = np.asarray(zone_center, float)
        self._t0 = np.nan
        self._next_plan = np.inf
        self._u = np.zeros(3)
        self._x_set = np.zeros(3)
        self._rot = np.eye(3)
        self._q_cmd: np.ndarray | None = None

    def start(self, t: float, q: np.ndarray) -> None:
        """The handover starts at ``t`` (s) with the arm at ``q``: times in the controller's
        timing count from here; the end effector's orientation is held from here on."""
        self.controller.reset()
        self._t0 = float(t)
        self._next_plan = float(t)
        pose = self.ik.pose(q)
        self._x_set = pose.translation.copy()
        self._rot = pose.rotation.copy()
        self._q_cmd = np.asarray(q, float).copy()
        self._u = np.zeros(3)

    @property
    def started(self) -> bool:
        return np.isfinite(self._t0)

    def elapsed(self, t: float) -> float:
        """Seconds since the handover's start."""
        return t - self._t0

    def update(
        self,
        t: float,
        dt: float,
        hand: np.ndarray,
        target: np.ndarray | None = None,
        robot_holds_object: bool = False,
        object_free: bool = False,
        object_position: np.ndarray | None = None,
        dropoff: np.ndarray | None = None,
    ) -> ReachStep:
        """Advance to ``t`` (``dt`` since the last call) toward ``hand`` (the point to take the
        object at); plans when a control period has passed. The object state and places
        (``object_free``, ``object_position``, ``dropoff``) go to the controller as
        :class:`~gazebot.apps.controllers.base.ReachObservation` describes them."""
        assert self._q_cmd is not None, "start() first"
        plan = None
        if t + 1e-9 >= self._next_plan:
            x_now = self.ik.pose(self._q_cmd).translation
            plan = self.controller.plan(
                ReachObservation(
                    t=self.elapsed(t),
                    x=x_now,
                    hand=np.asarray(hand, float),
                    target=target,
                    robot_holds_object=robot_holds_object,
                    zone_center=self.zone_center,
                    object_free=object_free,
                    object_position=object_position,
                    dropoff=dropoff,
                )
            )
            self._u = plan.command.copy()
            # Re-anchor the set point on the arm so tracking errors do not pile up.
            self._x_set = x_now.copy()
            self._next_plan += self.controller.dt
            while self._next_plan <= t:
                self._next_plan += self.controller.dt
        self._x_set = self._x_set + self._u * dt
        self._q_cmd = self.ik.step(self._q_cmd, self._u, self._x_set, self._rot, dt)
        return ReachStep(q=self._q_cmd.copy(), velocity=self._u.copy(), plan=plan)

    def hold(self) -> np.ndarray:
        """The last commanded joints (hold still there)."""
        assert self._q_cmd is not None
        return self._q_cmd.copy()
