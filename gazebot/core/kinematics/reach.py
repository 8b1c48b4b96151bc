"""What a robot's head can look at: the share of a workspace its gaze reaches, head alone and
head plus eyes, and the worst miss (``gazebot robots check``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gazebot.core.kinematics.look_at import IKConfig, solve_ik
from gazebot.core.kinematics.robot import RobotModel

#: A target counts as looked at when the gaze misses it by at most this angle (rad).
ON_TARGET = math.radians(0.5)


@dataclass(frozen=True)
class GazeReach:
    """The gaze's reach over sample points of a workspace ball.

    Attributes:
        radius: Workspace radius (m) around the gaze origin at rest.
        samples: Points tried (the half ball in front of the robot).
        head_share: Share of them the head alone looks at within :data:`ON_TARGET`.
        gaze_share: Share the head and eyes together look at within :data:`ON_TARGET`.
        worst_miss: Largest angle (rad) by which head and eyes miss a sample point.
        worst_point: That point (base frame, m).
    """

    radius: float
    samples: int
    head_share: float
    gaze_share: float
    worst_miss: float
    worst_point: tuple[float, float, float]


def workspace_points(robot: RobotModel, radius: float = 2.0, step: float = 0.25) -> np.ndarray:
    """Grid points (base frame) within ``radius`` of the gaze origin at rest, in front of it
    (the half space its line of sight at rest points into), at least ``step`` away from it."""
    pose = robot.gaze_pose(robot.rest)
    ticks = np.arange(-radius, radius + 1e-9, step)
    grid = np.stack(np.meshgrid(ticks, ticks, ticks, indexing="ij"), axis=-1).reshape(-1, 3)
    # Forward is the line of sight at rest, levelled (a head looking down still faces forward).
    forward = pose.line_of_sight * np.array([1.0, 1.0, 0.0])
    norm = float(np.linalg.norm(forward))
    forward = forward / norm if norm > 1e-6 else pose.line_of_sight
    dist = np.linalg.norm(grid, axis=1)
    keep = (dist <= radius) & (dist >= step) & (grid @ forward > 0.0)
    return pose.position + grid[keep]


def gaze_reach(
    robot: RobotModel, radius: float = 2.0, step: float = 0.25, ik: IKConfig | None = None
) -> GazeReach:
    """Solve the look-at for every :func:`workspace_points` point from the rest posture."""
    points = workspace_points(robot, radius, step)
    head_hits = gaze_hits = 0
    worst, worst_point = 0.0, (math.nan, math.nan, math.nan)
    for p in points:
        sol = solve_ik(robot, p, None, ik)
        head_hits += sol.residual <= ON_TARGET
        gaze_hits += sol.total_residual <= ON_TARGET
        if sol.total_residual > worst:
            worst, worst_point = sol.total_residual, (float(p[0]), float(p[1]), float(p[2]))
    n = len(points)
    return GazeReach(radius, n, head_hits / n, gaze_hits / n, worst, worst_point)
