"""The seed's Table 4.4: the share of human giving motions for which the STL reach controller
finds a feasible solution, per reach time ``t_1`` and speed cap ``u_max`` (section 4.4.3).

The seed, quoted: "Table 4.4 shows the percentage of the human giving motions from the
database for which the controller finds a feasible solution for a given reach-time value and a
maximum velocity control input u_max. The values of the remaining STL parameters are:
eps_p = 0.01m, delta_t = 0.2s, H = 20 time-steps." and "Since we only simulate the reach phase,
we first segment each trajectory into reach, transfer, and retreat phases".

So each motion's reach phase (:mod:`gazebot.apps.controllers.giving_motions`) is simulated in
closed loop, the hand sampled every ``delta_t``; the LDS hand model (eq. 4.5) has seen the hand
over its history window before the reach starts ("we use the pose data of the human for a
pre-defined time interval before the current time-step"). A motion succeeds when the MILP is
feasible at every control step of its reach phase (a failed step makes the robot stop, 4.4.1).
The strategy is the configured one (default reactive, towards human: the seed's Fig. 4.4).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

from gazebot.apps.controllers.config import ControllersConfig
from gazebot.apps.controllers.giving_motions import GivingMotion

log = logging.getLogger(__name__)

# Table 4.4 as the seed prints it: (u_max m/s, t_1 s) -> successful handovers (%).
SEED_TABLE_4_4: dict[tuple[float, float], float] = {
    (1.0, 1.0): 14.3,
    (1.0, 2.0): 91.4,
    (1.0, 3.0): 100.0,
    (0.5, 2.0): 2.9,
    (0.5, 3.0): 82.9,
    (0.5, 4.0): 97.1,
}
SEED_EPS_P_M = 0.01
SEED_DT_S = 0.2
SEED_HORIZON = 20


@dataclass(frozen=True)
class CellResult:
    """One row of the table: how many motions the controller served at ``u_max``, ``t_1``."""

    u_max_m_s: float
    reach_time_s: float
    succeeded: int
    motions: int

    @property
    def percent(self) -> float:
        return 100.0 * self.succeeded / self.motions if self.motions else math.nan

    @property
    def seed_percent(self) -> float | None:
        return SEED_TABLE_4_4.get((self.u_max_m_s, self.reach_time_s))


def table_config(base: ControllersConfig, u_max: float, reach_time: float) -> ControllersConfig:
    """``base`` with Table 4.4's parameters: ``u_max``, ``t_1``, ``eps_p = 0.01 m``,
    ``delta_t = 0.2 s``, ``H = 20``."""
    data = base.model_dump()
    data.update(u_max_m_s=u_max, reach_time_s=reach_time, dt_s=SEED_DT_S, stall_time_s=0.0)
    data["stl"].update(horizon=SEED_HORIZON, eps_p_m=SEED_EPS_P_M)
    return ControllersConfig.model_validate(data)


def reach_feasible(motion: GivingMotion, config: ControllersConfig) -> bool:
    """Whether the STL controller finds a feasible input at every control step of the motion's
    reach phase (module doc)."""
    from gazebot.apps.controllers.base import ReachObservation
    from gazebot.apps.controllers.stl import STLController

    ctrl = STLController(config)
    dt = config.dt_s
    t0 = float(motion.t[motion.reach_start])
    for k in range(config.stl.history_steps - 1, 0, -1):
        ctrl.model.observe(motion.hand_at(t0 - k * dt))  # the hand seen before the reach
    steps = max(1, math.ceil(motion.reach_duration_s / dt - 1e-9))
    x = motion.robot_start.copy()
    for j in range(steps):
        obs = ReachObservation(t=j * dt, x=x, hand=motion.hand_at(t0 + j * dt))
        plan = ctrl.plan(obs)
        if not plan.feasible:
            return False
        x = x + plan.command * dt
    return True


def table_4_4(
    motions: list[GivingMotion],
    base: ControllersConfig,
    cells: tuple[tuple[float, float], ...] = tuple(SEED_TABLE_4_4),
) -> list[CellResult]:
    """The success rate of every ``(u_max, t_1)`` cell over ``motions``."""
    out = []
    for u_max, t1 in cells:
        cfg = table_config(base, u_max, t1)
        ok = sum(reach_feasible(m, cfg) for m in motions)
        log.info("u_max %.2f m/s, t1 %.1f s: %d / %d feasible", u_max, t1, ok, len(motions))
        out.append(CellResult(u_max, t1, ok, len(motions)))
    return out
