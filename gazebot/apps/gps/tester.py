"""The trainer/tester: a 2-DoF arm (shoulder, elbow) with a cylindrical mass for a hand, standing in
for the human (seed 5.4), and its human-like joint trajectory (eq. 5.12).

The arm moves in the vertical plane through the learner's base axis at the tester's azimuth: its
shoulder stands ``shoulder_distance_m`` from that axis at ``shoulder_height_m``; at zero joint
angles the arm hangs straight down, positive angles swing it towards the learner. Eq. 5.12's
theta_0 is the configured ``rest_deg``: the seed's "theta_0,1 = theta_0,2 = 0" (configs/gps.yaml),
i.e. with our zero the arm hanging straight down, elbow extended. The seed does not say where its
arm's zero points; straight down is a person's relaxed arm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gazebot.apps.gps.config import TesterConfig


class UnreachableTarget(ValueError):
    """The tester's hand cannot reach the requested point."""


def human_like(t: float | np.ndarray, theta0: np.ndarray, thetaf: np.ndarray,
               cfg: TesterConfig) -> tuple[np.ndarray, np.ndarray]:
    """Eq. 5.12 (Rasch et al.): joint angles and velocities at time ``t`` [s].

    theta(t) = a (theta_f - theta_0) / (b + exp(-c t / t_f)) + theta_0. As written it starts at
    theta_0 + 9e-4 (theta_f - theta_0) and settles at theta_0 + (a / b)(theta_f - theta_0), 1.6%
    beyond theta_f; we keep the seed's coefficients and measure errors to where the hand really is.
    """
    t = np.asarray(t, dtype=float)[..., None]
    e = np.exp(-cfg.c * t / cfg.t_f_s)
    delta = np.asarray(thetaf) - np.asarray(theta0)
    q = cfg.a * delta / (cfg.b + e) + theta0
    qd = cfg.a * delta * (cfg.c / cfg.t_f_s) * e / (cfg.b + e) ** 2
    return q, qd


@dataclass(frozen=True)
class TesterMotion:
    """One trial of the tester: where it stands (azimuth [rad]) and how its two joints move."""

    azimuth: float
    theta0: tuple[float, float]
    thetaf: tuple[float, float]
    moving: bool

    def joints(self, t: float, cfg: TesterConfig) -> tuple[np.ndarray, np.ndarray]:
        """Joint angles and velocities [rad, rad/s] at time ``t``: fixed at ``thetaf`` when
        static, eq. 5.12 from ``theta0`` when moving."""
        if not self.moving:
            return np.array(self.thetaf, dtype=float), np.zeros(2)
        return human_like(t, np.array(self.theta0), np.array(self.thetaf), cfg)


def planar_ik(forward_m: float, up_m: float, cfg: TesterConfig) -> tuple[float, float]:
    """Shoulder and elbow angles putting the hand ``forward_m`` towards the learner and ``up_m``
    above the shoulder; the elbow flexes forwards (positive), like a person's reaching arm."""
    l1, l2 = cfg.upper_arm_m, cfg.forearm_m
    r2 = forward_m**2 + up_m**2
    cos_e = (r2 - l1**2 - l2**2) / (2 * l1 * l2)
    if not -1.0 <= cos_e <= 1.0:
        raise UnreachableTarget(
            f"tester hand cannot reach {math.sqrt(r2):.3f} m from its shoulder "
            f"(reach {abs(l1 - l2):.3f}..{l1 + l2:.3f} m)"
        )
    elbow = math.acos(cos_e)
    # Hand direction angle from straight down, towards the learner.
    phi = math.atan2(forward_m, -up_m)
    shoulder = phi - math.atan2(l2 * math.sin(elbow), l1 + l2 * math.cos(elbow))
    return shoulder, elbow


def planar_fk(shoulder: float, elbow: float, cfg: TesterConfig) -> tuple[float, float]:
    """(forward, up) of the hand relative to the shoulder."""
    fwd = cfg.upper_arm_m * math.sin(shoulder) + cfg.forearm_m * math.sin(shoulder + elbow)
    up = -cfg.upper_arm_m * math.cos(shoulder) - cfg.forearm_m * math.cos(shoulder + elbow)
    return fwd, up


def hand_position(azimuth: float, shoulder: float, elbow: float, cfg: TesterConfig) -> np.ndarray:
    """The tester's hand (centre of its cylinder) in the learner's base frame [m]."""
    fwd, up = planar_fk(shoulder, elbow, cfg)
    rho = cfg.shoulder_distance_m - fwd
    return np.array([rho * math.cos(azimuth), rho * math.sin(azimuth), cfg.shoulder_height_m + up])


def motion_to(point: np.ndarray, moving: bool, cfg: TesterConfig) -> TesterMotion:
    """The tester motion whose final joint angles (by IK) put its hand at ``point`` [m, base frame].

    Raises :class:`UnreachableTarget` if the point is out of the tester's reach.
    """
    x, y, z = (float(v) for v in point)
    azimuth = math.atan2(y, x)
    rho = math.hypot(x, y)
    shoulder, elbow = planar_ik(cfg.shoulder_distance_m - rho, z - cfg.shoulder_height_m, cfg)
    rest = tuple(math.radians(v) for v in cfg.rest_deg)
    return TesterMotion(azimuth, (rest[0], rest[1]), (shoulder, elbow), moving)
