"""Look-at IK and gaze controller cost against a closed-form pan/tilt (atan2) peer.

The peer is what a hand-written head controller does: pan = atan2(dy, dx), tilt = atan2(dz, d_xy)
from the head's rest gaze origin. It is far cheaper but ignores the head's link offsets (the
display moves when the head turns), joint limits and the eyes; its pointing error, measured
through our forward kinematics, is reported in the note.
"""

from __future__ import annotations

import math

import numpy as np

from benchmarks.common import Result, median_time


def _targets(robot, n: int, seed: int = 0) -> list[np.ndarray]:
    """Points where a giver's face, hand and the object are (in front, 0.5-1.5 m)."""
    rng = np.random.default_rng(seed)
    return list(rng.uniform([0.5, -0.6, 0.8], [1.5, 0.6, 1.8], size=(n, 3)))


def _track(robot, n: int) -> list[np.ndarray]:
    """A face moving smoothly (100 Hz samples), for warm starts and controller ticks."""
    face = robot.points["face"]
    return [face + [0.0, 0.3 * math.sin(0.02 * k), 0.1 * math.sin(0.05 * k)] for k in range(n)]


class ClosedFormPanTilt:
    """The peer: analytic pan/tilt from a fixed head origin (tilt shared by all tilt joints)."""

    def __init__(self, robot) -> None:
        self.origin = robot.gaze_pose(robot.rest).position.tolist()
        self.pan = robot.head_joints.index("head_pan")
        self.tilts = [i for i, n in enumerate(robot.head_joints) if "tilt" in n]
        self.lower, self.upper = robot.lower.tolist(), robot.upper.tolist()
        self.n = robot.n_head

    def solve(self, target) -> list[float]:
        ox, oy, oz = self.origin
        dx, dy, dz = target[0] - ox, target[1] - oy, target[2] - oz
        q = [0.0] * self.n
        q[self.pan] = math.atan2(dy, dx)
        if self.tilts:
            tilt = math.atan2(-dz, math.hypot(dx, dy)) / len(self.tilts)  # + = down
            for i in self.tilts:
                q[i] = tilt
        return [min(max(v, lo), hi) for v, lo, hi in zip(q, self.lower, self.upper, strict=True)]


def _peer_error_deg(robot, peer: ClosedFormPanTilt, targets) -> float:
    from gazebot.core.kinematics.eyes import angle_between

    errs = []
    for t in targets:
        pose = robot.gaze_pose(np.array(peer.solve(t)))
        errs.append(math.degrees(angle_between(pose.rotation[:, 0], t - pose.position)))
    return float(np.median(errs))


def run() -> list[Result]:
    from gazebot.core.kinematics import GazeController, RobotModel, solve_ik

    results: list[Result] = []
    for name in ("jaco2", "sawyer"):
        robot = RobotModel.load(name)
        peer = ClosedFormPanTilt(robot)
        cold_targets = _targets(robot, 40)
        track = _track(robot, 200)
        peer_name = "closed-form atan2 pan/tilt"

        def cold(robot=robot, targets=cold_targets):
            for t in targets:
                solve_ik(robot, t)

        def warm(robot=robot, targets=track):
            q = None
            for t in targets:
                q = solve_ik(robot, t, q0=q).q

        def peer_cold(peer=peer, targets=cold_targets):
            for t in targets:
                peer.solve(t)

        def peer_track(peer=peer, targets=track):
            for t in targets:
                peer.solve(t)

        controller = GazeController(robot)
        clock = [0.0]

        def ticks(controller=controller, targets=track, clock=clock):
            for t in targets:
                clock[0] += 0.01
                controller.update(clock[0], t)

        us = 1e6
        t_cold = median_time(cold, repeat=5) / len(cold_targets) * us
        t_warm = median_time(warm, repeat=5) / len(track) * us
        t_tick = median_time(ticks, repeat=5) / len(track) * us
        p_cold = median_time(peer_cold, repeat=5) / len(cold_targets) * us
        p_track = median_time(peer_track, repeat=5) / len(track) * us

        ours_res = float(
            np.median([math.degrees(solve_ik(robot, t).residual) for t in cold_targets])
        )
        peer_err = _peer_error_deg(robot, peer, cold_targets)
        accuracy = f"median head pointing error: ours {ours_res:.3g} deg, peer {peer_err:.3g} deg"
        if name == "sawyer":
            accuracy += " (pan only: the eyes take the elevation)"
        results += [
            Result(
                f"look-at IK cold start ({name})", t_cold, p_cold, "us", peer_name, note=accuracy
            ),
            Result(
                f"look-at IK warm start, moving face ({name})", t_warm, p_track, "us", peer_name
            ),
            Result(
                f"GazeController.update per tick ({name})",
                t_tick,
                p_track,
                "us",
                peer_name,
                note="IK (tracking: usually one Gauss-Newton step) + min-jerk plans + limits",
            ),
        ]
    return results
