"""Running one trial: a controller (local or global) acting on the scene for the trial's length."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gazebot.apps.gps.reach_scene import HandoverScene
from gazebot.apps.gps.state import StateKind, state_vector
from gazebot.apps.gps.tester import TesterMotion

# act(t, x) -> u: a controller's action at control step t for state x.
Act = Callable[[int, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Trial:
    """One trial: states X (T, dX) and applied actions U (T, dU) for learning, and per control
    instant (T + 1 of them, the final state included) the gripper and hand positions [m] and the
    norm of the applied joint torques [N m]."""

    X: np.ndarray
    U: np.ndarray
    p_r: np.ndarray
    p_h: np.ndarray
    torque_norm: np.ndarray
    dt: float

    def final_error(self, window_s: float = 0.5) -> float:
        """The seed's error: mean gripper-to-hand distance over the trial's last ``window_s``."""
        n = len(self.p_r)
        times = np.arange(n) * self.dt
        last = times >= times[-1] - window_s - 1e-9
        return float(np.linalg.norm(self.p_r[last] - self.p_h[last], axis=1).mean())


def run_trial(scene: HandoverScene, motion: TesterMotion, kind: StateKind, act: Act) -> Trial:
    """Reset the scene to ``motion`` and run ``act`` for the configured horizon."""
    horizon = scene.cfg.horizon
    obs = scene.reset(motion)
    xs, us, p_r, p_h, tq = [], [], [obs.p_r], [obs.p_h], [np.linalg.norm(obs.torque)]
    for t in range(horizon):
        x = state_vector(obs, kind)
        u = scene.clip(np.asarray(act(t, x), dtype=float))
        xs.append(x)
        us.append(u)
        obs = scene.step(u)
        p_r.append(obs.p_r)
        p_h.append(obs.p_h)
        tq.append(np.linalg.norm(obs.torque))
    return Trial(np.array(xs), np.array(us), np.array(p_r), np.array(p_h), np.array(tq),
                 scene.cfg.control_dt_s)
