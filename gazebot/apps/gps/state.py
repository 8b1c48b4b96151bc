"""The three state representations of seed section 5.3.1 (eqs. 5.8-5.10).

FULL     x = [theta_r, dtheta_r, theta_h, dtheta_h, p_o, p_h, p_r, dp_o, dp_h, dp_r, g_r]
REDUCED  x = [theta_r, dtheta_r, p_o, p_h, p_r, dp_o, dp_h, dp_r, g_r]
RELATIVE x = [theta_r, dtheta_r, p_o^r, p_h^r, dp_o^r, dp_h^r, g_r]  (in the gripper's frame)

p_o holds three points on the object (9 numbers). Our counts are FULL 49, REDUCED 45, RELATIVE 39;
the seed's RELATIVE has 54 (its point sets are not given), so the dimensions differ from its
Fig. 5.5 labels while the composition follows the equations.
"""

from __future__ import annotations

from enum import Enum

import numpy as np

from gazebot.apps.gps.reach_scene import Observation


class StateKind(str, Enum):
    FULL = "full"
    REDUCED = "reduced"
    RELATIVE = "relative"


DIMS = {StateKind.FULL: 49, StateKind.REDUCED: 45, StateKind.RELATIVE: 39}


def state_vector(obs: Observation, kind: StateKind) -> np.ndarray:
    """The state x_t of ``kind`` from one observation."""
    robot = [obs.theta_r, obs.dtheta_r]
    if kind is StateKind.RELATIVE:
        rt = obs.r_ee.T
        rel_p = (obs.p_o - obs.p_r) @ rt.T  # rows: R^T (p - p_r)
        rel_h = rt @ (obs.p_h - obs.p_r)
        # d/dt R^T (p - p_r) = R^T (dp - dp_r) - R^T (w x (p - p_r)).
        w = obs.w_ee
        rel_dp = (obs.dp_o - obs.dp_r - np.cross(w, obs.p_o - obs.p_r)) @ rt.T
        rel_dh = rt @ (obs.dp_h - obs.dp_r - np.cross(w, obs.p_h - obs.p_r))
        parts = robot + [rel_p.ravel(), rel_h, rel_dp.ravel(), rel_dh, [obs.g_r]]
    else:
        human = [obs.theta_h, obs.dtheta_h] if kind is StateKind.FULL else []
        parts = robot + human + [obs.p_o.ravel(), obs.p_h, obs.p_r, obs.dp_o.ravel(), obs.dp_h,
                                 obs.dp_r, [obs.g_r]]
    return np.concatenate([np.asarray(p, dtype=float).ravel() for p in parts])


def gap_selector(kind: StateKind) -> np.ndarray:
    """The (3, dX) matrix S with S x = p_r - p_h (the gripper-to-hand vector, eq. 5.11); in the
    RELATIVE state it is -p_h^r, whose norm is the same."""
    dx = DIMS[kind]
    s = np.zeros((3, dx))
    eye = np.eye(3)
    if kind is StateKind.RELATIVE:
        i_h = 14 + 9
        s[:, i_h:i_h + 3] = -eye
    else:
        base = 14 + (4 if kind is StateKind.FULL else 0)
        i_h, i_r = base + 9, base + 12
        s[:, i_r:i_r + 3] = eye
        s[:, i_h:i_h + 3] = -eye
    return s
