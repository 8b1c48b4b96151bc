"""``stl``: the reach phase synthesized from the seed's STL specification as a mixed-integer
linear program in receding horizon (sections 4.2.2-4.4.1, eqs. 4.1-4.5, Table 4.3).

Each control step solves

    min sum_k ||u_k||_1                                   (eq. 4.4, l1 as in 4.4.1)
    s.t. x_{k+1} = x_k + u_k dt, u_min <= u <= u_max      (eq. 4.2)
         the horizon's trace satisfies  [](trigger => <>_[0, t_1] ||target - p_r||_1 < eps_p)

with the trigger and target of the strategy (Table 4.3): ``proactive`` triggers while the object
is not with the robot (receiver; with the robot for a giver, t_7), ``reactive`` also needs the
human hand in the handover zone (``||p_h - c|| <= l_h``); ``towards-human`` targets the hand
predicted by the least-squares LDS (eq. 4.5), ``predetermined`` a fixed handover location.
The same synthesis serves Table 4.2's other position specifications, picked from the object
state each step: a giver with the object on the ground (``o == o_g``) goes to it first
(``[](o == o_g => <>_[0, t_5] ||p_o - p_r|| < eps_p)``, the pick-up), and a receiver holding
the object (``o == o_r``) with a drop-off location carries it there
(``[](o == o_r => <>_[0, t_3] ||p_r - p_d|| < eps_p)``, the retreat). The gripper's
specifications (t_2, t_4, t_6, t_8) are :class:`~gazebot.apps.controllers.stl_gripper.STLGripper`'s.
The "eventually" is encoded with one binary per future step (big-M on the l1 distance); each
triggered window, including one opened in the past and not yet met, needs a near step. Windows
that end beyond the horizon are left to later steps (as the receding-horizon synthesis of
Raman et al. does). "If no feasible control input is found, the robot stops." Solved with HiGHS
(``scipy.optimize.milp``; the matrices in :mod:`gazebot.apps.controllers.stl_milp`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from gazebot.apps.controllers.base import ReachController, ReachObservation, VelocityPlan
from gazebot.apps.controllers.config import ControllersConfig, Role
from gazebot.apps.controllers.human_model import LinearHandModel
from gazebot.apps.controllers.stl_milp import ReachMILP, solve_reach_milp


@dataclass(frozen=True)
class ActiveSpec:
    """The Table 4.2/4.3 position specification a step synthesizes:
    ``[](trigger => <>_[0, steps dt] ||target - p_r||_1 < eps_p)`` over the horizon."""

    name: str  # its time bound: "t1", "t3", "t5" or "t7"
    trigger: np.ndarray  # (H + 1,) bool, at x_0..x_H
    target: np.ndarray  # (H + 1, 3)
    steps: int


class STLController(ReachController):
    """Receding-horizon MILP synthesis of the Table 4.3 reach specification and of Table 4.2's
    pick-up (t_5) and carry to the drop-off (t_3); ``active`` names the last step's."""

    name = "stl"

    def __init__(self, config: ControllersConfig) -> None:
        super().__init__(config)
        self.stl = config.stl
        self.model = LinearHandModel(config.dt_s, config.stl.history_steps)
        self.reset()

    def reset(self) -> None:
        self.model.reset()
        self.last_milp: ReachMILP | None = None  # the last step's problem (benchmarks, debugging)
        self.active: ActiveSpec | None = None  # the last step's specification
        self._pending: int | None = None  # step the oldest unmet trigger fired

    def _triggered(self, hand: np.ndarray, holds: bool, center: np.ndarray) -> np.ndarray:
        """The strategy's trigger at each hand sample (Table 4.3 antecedents)."""
        obj = holds if self.stl.role is Role.GIVER else not holds
        trig = np.full(len(hand), obj)
        if self.stl.strategy.reactive:
            trig &= np.linalg.norm(hand - center, axis=1) <= self.stl.zone_radius_m
        return trig

    def _spec(self, obs: ReachObservation, hand: np.ndarray) -> ActiveSpec:
        """Which position specification binds now (the object state picks it; module doc)."""
        H = self.stl.horizon
        always = np.ones(H + 1, bool)
        giver = self.stl.role is Role.GIVER
        if giver and obs.object_free and obs.object_position is not None:
            at = np.tile(np.asarray(obs.object_position, float), (H + 1, 1))
            return ActiveSpec("t5", always, at, self.steps(self.stl.pickup_time_s))
        if not giver and obs.robot_holds_object and obs.dropoff is not None:
            at = np.tile(np.asarray(obs.dropoff, float), (H + 1, 1))
            return ActiveSpec("t3", always, at, self.steps(self.stl.retreat_time_s))
        if self.stl.strategy.towards_human:
            target = hand
        else:
            if obs.target is None:
                raise ValueError(f"strategy {self.stl.strategy.value} needs a handover location")
            target = np.tile(np.asarray(obs.target, float), (H + 1, 1))
        trig = self._triggered(hand, obs.robot_holds_object, np.asarray(obs.zone_center, float))
        name = "t7" if giver else "t1"
        return ActiveSpec(name, trig, target, self.steps(self.config.reach_time_s))

    def plan(self, obs: ReachObservation) -> VelocityPlan:
        t_start = time.perf_counter()
        H, eps = self.stl.horizon, self.stl.eps_p_m
        k = self.steps(obs.t)
        x0 = np.asarray(obs.x, float)
        self.model.observe(obs.hand)
        spec = self._spec(obs, self.model.predict(H))  # hand at j = 0..H
        if self.active is not None and spec.name != self.active.name:
            self._pending = None  # a new specification: its own windows
        self.active = spec
        trig, target, n1 = spec.trigger, spec.target, spec.steps
        near_now = float(np.abs(x0 - target[0]).sum()) < eps
        if near_now:
            self._pending = None
        elif trig[0] and self._pending is None:
            self._pending = k
        W = np.zeros((H + 1, H))
        r = np.zeros(H + 1)
        feasible_so_far = True
        if self._pending is not None:
            deadline = self._pending + n1 - k  # steps from now
            if deadline < 1:
                feasible_so_far = False  # the window closed unmet: the spec is already violated
            elif deadline <= H:
                W[0, :deadline] = 1.0
                r[0] = 1.0
        for s in range(1, H + 1):
            if trig[s] and s + n1 <= H:
                W[s, s - 1 : s + n1] = 1.0  # b index j-1 is x_j
                r[s] = 1.0
        U = None
        status = "deadline_passed"
        if feasible_so_far:
            problem = ReachMILP(
                x0=x0,
                target=target[1:],
                windows=W,
                required=r,
                dt=self.dt,
                u_max=self.config.u_max_m_s,
                eps=eps - self.stl.margin_m,
            )
            self.last_milp = problem
            U, status = solve_reach_milp(problem, self.stl.mip_gap)
            if U is not None:
                U = self.cap(U)
        feasible = U is not None
        if U is None:
            U = np.zeros((H, 3))  # "If no feasible control input is found, the robot stops."
        return VelocityPlan.integrated(obs.t, self.dt, x0, U, feasible, t_start, status)
