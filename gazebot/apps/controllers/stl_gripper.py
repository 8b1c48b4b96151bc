"""The gripper's part of the seed's STL synthesis: its openness ``g_r`` is one more integrator of
the system (eq. 4.2: ``x_dot = [p_r_dot, q_r_dot, g_r_dot] = u``, ``u_min <= u <= u_max``), and
Table 4.2's gripper specifications have the reach's shape,
``[](trigger => <>_[0, t_i] |g_r - goal| < eps_g)``:

- t_2 (receiver transfer) and t_6 (giver pick-up): close to the grip width, ``goal = g*``;
- t_4 (receiver at the drop-off) and t_8 (giver transfer): open, ``goal = 1``.

Each control step solves the reach's MILP (:mod:`gazebot.apps.controllers.stl_milp`) on the 1-D
state:
min ``sum |u_g|`` (eq. 4.4) with ``|u_g| <= gripper_speed_per_s``; a window opened by the trigger
and not yet met needs a near step, as in :class:`~gazebot.apps.controllers.stl.STLController`; "If
no feasible control input is found, the robot stops" (the gripper holds its openness).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gazebot.apps.controllers.config import STLConfig
from gazebot.apps.controllers.stl_milp import ReachMILP, solve_reach_milp


@dataclass(frozen=True)
class GripperPlan:
    """Planned openness velocities (1/s) from ``t0`` (s), one per ``dt``, and the openness they
    lead to (one more); ``feasible`` False when no input meets the window (then all zero)."""

    t0: float
    dt: float
    velocities: np.ndarray
    openness: np.ndarray
    feasible: bool
    status: str = "optimal"

    @property
    def command(self) -> float:
        """The openness velocity to apply now (1/s)."""
        return float(self.velocities[0]) if len(self.velocities) else 0.0


class STLGripper:
    """Receding-horizon synthesis of one gripper specification at a time.

    Args:
        config: The STL configuration (horizon, ``eps_g``, ``gripper_margin``, speed).
        dt: The control period (s).
    """

    def __init__(self, config: STLConfig, dt: float) -> None:
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be a positive number of seconds, got {dt}")
        self.stl = config
        self.dt = float(dt)
        self.reset()

    def reset(self) -> None:
        """Forget the open window (a new specification starts)."""
        self._pending: int | None = None

    def steps(self, seconds: float) -> int:
        """Control steps in ``seconds``, rounded down (a deadline is never later than asked)."""
        return int(math.floor(seconds / self.dt + 1e-6))

    def plan(
        self, t: float, openness: float, goal: float, trigger: bool, within_s: float
    ) -> GripperPlan:
        """Plan from ``openness`` (0 closed .. 1 open) at ``t`` (s since the specification's
        clock started) so that ``|g_r - goal| < eps_g`` within ``within_s`` of the trigger
        (held for the whole horizon once it holds now)."""
        if not (math.isfinite(openness) and math.isfinite(goal) and math.isfinite(t)):
            raise ValueError("gripper openness, goal and time must be finite")
        H, eps = self.stl.horizon, self.stl.eps_g
        k, n = self.steps(t), self.steps(within_s)
        stop = np.zeros(H)
        flat = np.full(H + 1, float(openness))
        if abs(openness - goal) < eps:
            self._pending = None
            return GripperPlan(t, self.dt, stop, flat, True, "met")
        if trigger and self._pending is None:
            self._pending = k
        W = np.zeros((H + 1, H))
        r = np.zeros(H + 1)
        if self._pending is not None:
            deadline = self._pending + n - k
            if deadline < 1:  # the window closed unmet: the spec is already violated
                return GripperPlan(t, self.dt, stop, flat, False, "deadline_passed")
            if deadline <= H:
                W[0, :deadline] = 1.0
                r[0] = 1.0
        if trigger:
            for s in range(1, H + 1):
                if s + n <= H:
                    W[s, s - 1 : s + n] = 1.0
                    r[s] = 1.0
        problem = ReachMILP(
            x0=np.array([float(openness)]),
            target=np.full((H, 1), float(goal)),
            windows=W,
            required=r,
            dt=self.dt,
            u_max=self.stl.gripper_speed_per_s,
            eps=eps - self.stl.gripper_margin,
        )
        U, status = solve_reach_milp(problem, self.stl.mip_gap)
        if U is None:
            return GripperPlan(t, self.dt, stop, flat, False, status)
        u = np.clip(U[:, 0], -self.stl.gripper_speed_per_s, self.stl.gripper_speed_per_s)
        g = np.clip(openness + np.r_[0.0, np.cumsum(u * self.dt)], 0.0, 1.0)
        return GripperPlan(t, self.dt, u, g, True, status)
