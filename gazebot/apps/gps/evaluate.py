"""Evaluation as in seed section 5.4: the global policy against a static or moving tester whose hand
ends on each location of the shell; error = mean gripper-to-hand distance over the last 0.5 s."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import spearmanr

from gazebot.apps.gps.badmm import policy_act
from gazebot.apps.gps.policy_store import TrainedPolicy
from gazebot.apps.gps.reach_scene import HandoverScene
from gazebot.apps.gps.shell import shell_grid
from gazebot.apps.gps.tester import motion_to
from gazebot.apps.gps.trial import run_trial


@dataclass(frozen=True)
class Evaluation:
    """Per test location: the tester hand's final position [m], the error [m] and the mean norm
    of the applied joint torques [N m]; and the same error at the training targets."""

    points: np.ndarray
    errors: np.ndarray
    torques: np.ndarray
    train_errors: np.ndarray
    moving: bool
    mass_kg: float
    distances: np.ndarray  # each test location's distance to the nearest training target [m]

    def summary(self) -> dict:
        return {
            "train_error_m": float(self.train_errors.mean()),
            "test_error_mean_m": float(self.errors.mean()),
            "test_error_std_m": float(self.errors.std()),
            "test_error_max_m": float(self.errors.max()),
            "n": int(self.errors.size),
            "mean_torque_nm": float(self.torques.mean()),
            # Fig. 5.2's "error increases as the target location is shifted away from the
            # training locations": rank correlation of error with that distance.
            "error_distance_spearman": float(spearmanr(self.errors, self.distances)[0]),
        }

    def save(self, path) -> None:
        np.savez(path, points=self.points, errors=self.errors, torques=self.torques,
                 train_errors=self.train_errors, moving=self.moving, mass_kg=self.mass_kg,
                 distances=self.distances)


def evaluate(trained: TrainedPolicy, moving: bool, mass_kg: float | None = None,
             grid: int | None = None, progress: bool = False) -> Evaluation:
    """Run the policy once per shell location (``grid`` per azimuth; the config's 11 by default)."""
    from tqdm import tqdm

    cfg = trained.cfg
    scene = HandoverScene(cfg.scene, mass_kg)
    act = policy_act(trained.policy)
    tcfg = cfg.scene.tester
    # Training performance: the trainer's own kind of motion at the training targets.
    train = np.array([
        run_trial(scene, motion_to(p, trained.moving, tcfg), trained.kind, act).final_error()
        for p in trained.targets
    ])
    pts = shell_grid(cfg.shell, grid)
    finals, errors, torques = [], [], []
    for p in tqdm(pts, desc=f"evaluate ({'moving' if moving else 'static'})", unit="trial",
                  disable=not progress):
        trial = run_trial(scene, motion_to(p, moving, tcfg), trained.kind, act)
        finals.append(trial.p_h[-1])
        errors.append(trial.final_error())
        torques.append(trial.torque_norm[1:].mean())
    dist = np.min(np.linalg.norm(pts[:, None] - trained.targets[None], axis=2), axis=1)
    return Evaluation(np.array(finals), np.array(errors), np.array(torques), train, moving,
                      cfg.scene.ee_mass_kg if mass_kg is None else mass_kg, dist)
