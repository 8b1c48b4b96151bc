"""``mcj``: the seed's minimum cumulative jerk controller (section 3.2.1, eqs. 3.2-3.3).

"Users can specify the maximum reaching time of the robot and the controller generates a minimum
jerk trajectory towards the human hand within the specified time limit." The objective (eq. 3.2,
the sum of u's second derivative) is the sum of squared second differences of the velocity,
counting the two velocities applied before the plan (zero at the handover's start)."""

from __future__ import annotations

import cvxpy as cp

from gazebot.apps.controllers.config import MPCConfig
from gazebot.apps.controllers.mpc import TimedMPC


class MCJController(TimedMPC):
    """Minimum cumulative jerk toward the hand, reaching it by the reach time."""

    name = "mcj"
    zero_first_step = True  # eq. 3.3d

    @property
    def mpc(self) -> MPCConfig:
        return self.config.mcj

    def objective(
        self, X: cp.Expression, U_ext: cp.Expression, hand: cp.Parameter
    ) -> cp.Expression:
        jerk = U_ext[2:] - 2 * U_ext[1:-1] + U_ext[:-2]
        return cp.sum_squares(jerk)
