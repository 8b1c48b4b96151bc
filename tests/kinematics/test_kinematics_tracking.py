"""The fast tracking path: a slowly moving target is followed with one IK step per tick, never
further from a full solve than the tracking tolerance, and solved fully once it stops."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.kinematics import GazeController, RobotModel
from gazebot.kinematics.look_at import IKConfig


def _head_error(robot: RobotModel, head: dict[str, float], target: np.ndarray) -> float:
    pose = robot.gaze_pose(robot.head_vector(head))
    sight = pose.rotation[:, 0]
    to_target = target - pose.position
    cos = float(sight @ to_target / np.linalg.norm(to_target))
    return math.acos(min(1.0, max(-1.0, cos)))


@pytest.fixture(scope="module")
def jaco2() -> RobotModel:
    return RobotModel.load("jaco2")


def test_tracking_goals_stay_within_the_tracking_tolerance_of_the_target(jaco2):
    ctrl = GazeController(jaco2)
    loose = IKConfig().tracking_tolerance
    errors = []
    for i in range(240):  # 2 s at 120 Hz, the hand drifting 0.1 m/s sideways and down
        t = i / 120
        target = np.array([0.75, -0.1 + 0.1 * t, 1.1 - 0.05 * t])
        state = ctrl.update(t, target)
        if i > 0:
            errors.append(_head_error(jaco2, state.head_goal, target))
    assert max(errors) <= loose + 1e-6


def test_a_target_that_stops_ends_with_a_fully_solved_goal(jaco2):
    ctrl = GazeController(jaco2)
    target = None
    for i in range(120):
        t = i / 120
        target = np.array([0.75, -0.1 + 0.1 * t, 1.1])
        ctrl.update(t, target)
    for i in range(120, 130):  # the target stands still
        state = ctrl.update(i / 120, target)
    assert _head_error(jaco2, state.head_goal, target) <= IKConfig().tolerance + 1e-7


def test_absurdly_far_target_is_held_like_a_missing_sample(jaco2):
    from gazebot.kinematics import solve_ik

    sol = solve_ik(jaco2, np.array([1e308, 1e308, 1e308]))
    assert not sol.valid and "farther" in sol.message
    ctrl = GazeController(jaco2)
    good = ctrl.update(0.0, np.array([0.8, 0.1, 1.2]))
    held = ctrl.update(0.1, np.array([1e300, 0.0, 0.0]))
    assert not held.target_valid
    assert all(math.isfinite(v) for v in held.head.values())
    assert held.head_goal == good.head_goal


def test_robot_yaml_pointing_at_a_broken_mjcf_names_the_file(tmp_path):
    import yaml

    from gazebot.config import ConfigError, configs_dir

    mjcf = tmp_path / "empty.xml"
    mjcf.write_text("<mujoco><worldbody/></mujoco>")
    cfg = yaml.safe_load((configs_dir() / "robots" / "jaco2.yaml").read_text())
    cfg["mjcf"] = str(mjcf)
    path = tmp_path / "broken.yaml"
    path.write_text(yaml.safe_dump(cfg))
    with pytest.raises(ConfigError) as err:
        RobotModel.load(path)
    assert "empty.xml" in str(err.value)
