"""``mce``: the seed's minimum cumulative error controller (section 3.2.2, eqs. 3.4-3.5).

"The robot will try to minimize the total distance from the human hand over the whole
trajectory ... users can specify a stall time along with the maximum reaching time of the robot
and the controller generates an MCE trajectory after stalling for the specified amount of time."
"""

from __future__ import annotations

import cvxpy as cp

from gazebot.apps.controllers.config import MPCConfig
from gazebot.apps.controllers.mpc import TimedMPC


class MCEController(TimedMPC):
    """Minimum cumulative squared distance to the hand, still until the stall time (eq. 3.5)."""

    name = "mce"

    @property
    def mpc(self) -> MPCConfig:
        return self.config.mce

    @property
    def stall_time_s(self) -> float:
        return self.config.stall_time_s

    def objective(
        self, X: cp.Expression, U_ext: cp.Expression, hand: cp.Parameter
    ) -> cp.Expression:
        return cp.sum_squares(X[1:] - hand[1:])
