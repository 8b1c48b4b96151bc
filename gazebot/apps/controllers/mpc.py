"""The seed's timing-specified receding-horizon QP (section 3.2, eqs. 3.1-3.5), shared by ``mcj``
and ``mce``, which differ only in the objective and in how the start is held still.

Constraints (eqs. 3.3a-f, 3.5), over the horizon of ``L`` steps from the current state:
``x_{i+1} = x_i + u_i dt``; ``|u_i| <= u_max``; ``x_0`` = the end effector now; near the hand
(``||x - h|| <= eps_x``) from the step of the user's reach time on, with ``||u|| <= eps_u`` on the
step that arrives there; zero velocity on the first step of the handover (MCJ, eq. 3.3d) or
until the stall time (MCE, eq. 3.5). Times count from the handover's start, so as the horizon
recedes the deadline stays put; the horizon stretches when the deadline lies beyond it. Once the
reach time has passed, the plan must stay at the hand.

When no input meets the timing, the plan is marked infeasible (the seed: "feedback is provided
to the user that the robot is unable to reach the handover location within the specified
constraints") and the robot does its best instead: the same problem with the timing made a
heavily weighted penalty (our choice; the seed does not say what its robot then did).
The problems are built once per horizon length as parametrized cvxpy problems and solved with
Clarabel (second-order cones for the Euclidean tolerances).
"""

from __future__ import annotations

import time
from abc import abstractmethod
from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from gazebot.apps.controllers.base import ReachController, ReachObservation, VelocityPlan
from gazebot.apps.controllers.config import ControllersConfig, MPCConfig, SpeedLimit

BIG_M = 100.0  # m or m/s: a tolerance that is no constraint
SOFT_WEIGHT = 1e4  # weight of the timing penalty in the best-effort fallback


@dataclass
class _Problem:
    problem: cp.Problem
    U: cp.Variable
    x0: cp.Parameter
    hand: cp.Parameter
    ucap: cp.Parameter
    xtol: cp.Parameter
    utol: cp.Parameter
    u_prev: cp.Parameter


class TimedMPC(ReachController):
    """Receding-horizon QP with the seed's reach (and stall) time; subclasses give the objective."""

    #: Eq. 3.3d: zero velocity on the handover's first step (MCJ). MCE uses the stall (eq. 3.5).
    zero_first_step: bool = False

    def __init__(self, config: ControllersConfig) -> None:
        super().__init__(config)
        self._problems: dict[tuple[int, bool], _Problem] = {}
        self.reset()

    @property
    @abstractmethod
    def mpc(self) -> MPCConfig:
        """This controller's horizon and tolerances."""

    @property
    def stall_time_s(self) -> float:
        return 0.0

    @abstractmethod
    def objective(
        self, X: cp.Expression, U_ext: cp.Expression, hand: cp.Parameter
    ) -> cp.Expression:
        """The cost of positions ``X`` (L + 1, 3), velocities with the two applied before them
        ``U_ext`` (L + 2, 3) and the predicted hand ``hand`` (L + 1, 3)."""

    def reset(self) -> None:
        self._u_prev = np.zeros((2, 3))
        self._first = True

    # ------------------------------------------------------------------------------ problem
    def _build(self, L: int, soft: bool) -> _Problem:
        dt = self.dt
        U = cp.Variable((L, 3), name="u")
        x0 = cp.Parameter(3, name="x0")
        hand = cp.Parameter((L + 1, 3), name="hand")
        ucap = cp.Parameter(L, nonneg=True, name="ucap")
        xtol = cp.Parameter(L, nonneg=True, name="xtol")
        utol = cp.Parameter(L, nonneg=True, name="utol")
        u_prev = cp.Parameter((2, 3), name="u_prev")
        # x_{i+1} = x_i + u_i dt (eq. 3.3a) as a cumulative sum from x_0 (eq. 3.3c).
        lower = np.tril(np.ones((L, L))) * dt
        X = cp.vstack(
            [
                cp.reshape(x0, (1, 3), order="C"),
                np.ones((L, 1)) @ cp.reshape(x0, (1, 3), order="C") + lower @ U,
            ]
        )
        cons = []
        if self.config.speed_limit is SpeedLimit.PER_AXIS:
            cons.append(cp.abs(U) <= cp.reshape(ucap, (L, 1), order="C") @ np.ones((1, 3)))
        else:
            cons.append(cp.norm(U, 2, axis=1) <= ucap)
        gap = cp.norm(X[1:] - hand[1:], 2, axis=1)
        speed = cp.norm(U, 2, axis=1)
        cost = self.objective(X, cp.vstack([u_prev, U]), hand)
        if soft:
            s_x = cp.Variable(L, nonneg=True)
            s_u = cp.Variable(L, nonneg=True)
            cons += [gap <= xtol + s_x, speed <= utol + s_u]
            cost = cost + SOFT_WEIGHT * (cp.sum(s_x) + cp.sum(s_u))
        else:
            cons += [gap <= xtol, speed <= utol]
        problem = cp.Problem(cp.Minimize(cost), cons)
        return _Problem(problem, U, x0, hand, ucap, xtol, utol, u_prev)

    def _problem(self, L: int, soft: bool) -> _Problem:
        key = (L, soft)
        if key not in self._problems:
            self._problems[key] = self._build(L, soft)
        return self._problems[key]

    # ------------------------------------------------------------------------------ planning
    def horizon_for(self, t: float) -> tuple[int, int, int]:
        """``(L, n_reach, n_stall)``: horizon length and the steps from now to the reach time
        and to the stall time (<= 0 once passed)."""
        k = self.steps(t)
        n_reach = self.steps(self.config.reach_time_s) - k
        n_stall = self.steps_up(self.stall_time_s) - k
        return max(self.mpc.horizon, n_reach), n_reach, n_stall

    def plan(self, obs: ReachObservation) -> VelocityPlan:
        t_start = time.perf_counter()
        L, n_reach, n_stall = self.horizon_for(obs.t)
        goal = obs.hand if obs.target is None else np.asarray(obs.target, float)
        x0 = np.asarray(obs.x, float)
        idx = np.arange(L)
        still = idx < n_stall
        if self.zero_first_step and self._first:
            still[0] = True
        ucap = np.where(still, 0.0, self.config.u_max_m_s)
        # x index i + 1 for u index i: near the hand from the reach step on (or at once if passed).
        xtol = np.where(idx + 1 >= max(n_reach, 1), self.mpc.eps_x_m, BIG_M)
        utol = np.where(idx == n_reach - 1, self.mpc.eps_u_m_s, BIG_M)
        status, U = "optimal", None
        for soft in (False, True):
            p = self._problem(L, soft)
            p.x0.value = x0
            # The seed's static hand model over the horizon (eq. 3.7).
            p.hand.value = np.tile(goal, (L + 1, 1))
            p.ucap.value = ucap
            p.xtol.value = xtol
            p.utol.value = utol
            p.u_prev.value = self._u_prev
            try:
                p.problem.solve(solver=cp.CLARABEL)
                st = p.problem.status
            except cp.SolverError as exc:  # numerical trouble counts as no solution
                st = f"solver_error: {exc}"
            if st in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) and p.U.value is not None:
                U = np.asarray(p.U.value, float)
                break
            status = str(st)
        feasible = status == "optimal"
        if U is None:  # even the fallback failed: stand still
            U = np.zeros((L, 3))
        U = np.array([self.cap(u) for u in U])
        U[still] = 0.0
        self._u_prev = np.vstack([self._u_prev[1], U[0]])
        self._first = False
        return VelocityPlan.integrated(obs.t, self.dt, x0, U, feasible, t_start, status)
