"""``pv``: the seed's baseline proportional velocity controller (section 3.2.3, eq. 3.6).

The seed writes ``u_t = k_p ||x_t - h_t||`` and caps ``||u_t|| <= u_max``; a velocity needs a
direction, so we command ``u_t = k_p (h_t - x_t)`` (toward the hand, speed proportional to the
distance), saturated by the speed limit. PV has no timing parameters and is always feasible."""

from __future__ import annotations

import time

import numpy as np

from gazebot.apps.controllers.base import ReachController, ReachObservation, VelocityPlan


class PVController(ReachController):
    """``u = k_p (h - x)`` saturated at ``u_max`` (eq. 3.6)."""

    name = "pv"

    def plan(self, obs: ReachObservation) -> VelocityPlan:
        t0 = time.perf_counter()
        goal = obs.hand if obs.target is None else np.asarray(obs.target, float)
        u = self.cap(self.config.pv.k_p * (goal - np.asarray(obs.x, float)))[None, :]
        return VelocityPlan.integrated(obs.t, self.dt, obs.x, u, True, t0)
