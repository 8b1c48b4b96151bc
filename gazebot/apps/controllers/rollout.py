"""Closed-loop reach in Cartesian space: the controller plans every ``dt``, the end effector
follows the first velocity exactly (the seed's simulations of section 4.4.2). Used by
``gazebot reach-plan``, the tests and the benchmarks; the MuJoCo scene tracks the same plans
with the arm instead."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gazebot.apps.controllers.base import ReachController, ReachObservation, VelocityPlan


@dataclass(frozen=True)
class Rollout:
    """One closed-loop reach: ``times`` (s from the handover's start), end-effector
    ``positions`` and ``hands`` at those times, the applied ``velocities`` (one fewer), each
    step's feasibility and solve time, and the first plan (open loop, from the start)."""

    times: np.ndarray
    positions: np.ndarray
    hands: np.ndarray
    velocities: np.ndarray
    feasible_steps: np.ndarray
    solve_ms: np.ndarray
    first_plan: VelocityPlan

    @property
    def feasible(self) -> bool:
        """True when every step found an input meeting the timing."""
        return bool(np.all(self.feasible_steps))

    def gap(self, goal: np.ndarray | None = None) -> np.ndarray:
        """Euclidean end-effector distance (m) at each time to the hand, or to a fixed ``goal``
        (a predetermined handover location)."""
        to = self.hands if goal is None else np.asarray(goal, float)
        return np.linalg.norm(self.positions - to, axis=1)

    def reached_at(self, tol: float, goal: np.ndarray | None = None) -> float | None:
        """First time the end effector is within ``tol`` (m) of the hand (or ``goal``), None
        if never."""
        hit = np.nonzero(self.gap(goal) <= tol)[0]
        return float(self.times[hit[0]]) if hit.size else None


def run_reach(
    controller: ReachController,
    start: np.ndarray,
    hand: np.ndarray | Callable[[float], np.ndarray],
    duration_s: float,
    target: np.ndarray | None = None,
    zone_center: np.ndarray | None = None,
    robot_holds_object: bool = False,
) -> Rollout:
    """Run ``controller`` from ``start`` toward ``hand`` (a point or ``t -> point``) for
    ``duration_s`` seconds of control steps; ``robot_holds_object`` is the object state
    throughout (True for a giving robot's reach)."""
    controller.reset()
    dt = controller.dt
    if callable(hand):
        hand_at = hand
    else:
        still = np.asarray(hand, float)

        def hand_at(_t: float) -> np.ndarray:
            return still

    x = np.asarray(start, float).copy()
    n = int(round(duration_s / dt))
    times, xs, hs, us, ok, ms = [], [], [], [], [], []
    first: VelocityPlan | None = None
    for k in range(n + 1):
        t = k * dt
        h = np.asarray(hand_at(t), float)
        times.append(t)
        xs.append(x.copy())
        hs.append(h)
        if k == n:
            break
        obs = ReachObservation(
            t=t,
            x=x,
            hand=h,
            target=target,
            robot_holds_object=robot_holds_object,
            zone_center=np.zeros(3) if zone_center is None else zone_center,
        )
        plan = controller.plan(obs)
        first = first or plan
        u = plan.command
        us.append(u)
        ok.append(plan.feasible)
        ms.append(plan.solve_ms)
        x = x + u * dt
    assert first is not None or n == 0
    return Rollout(
        times=np.array(times),
        positions=np.array(xs),
        hands=np.array(hs),
        velocities=np.array(us).reshape(-1, 3),
        feasible_steps=np.array(ok, bool),
        solve_ms=np.array(ms),
        first_plan=first
        if first is not None
        else controller.plan(ReachObservation(t=0.0, x=x, hand=np.asarray(hand_at(0.0), float))),
    )
