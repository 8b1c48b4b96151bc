"""The fast tracking path: a slowly moving target is followed with one IK step per tick, never
further from a full solve than the tracking tolerance, and solved fully once it stops."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.core.kinematics import GazeController, RobotModel
from gazebot.core.kinematics.look_at import IKConfig


def _head_error(robot: RobotModel, head: dict[str, float], target: np.ndarray) -> float:
    pose = robot.gaze_pose(robot.head_vector(head))
    sight = pose.rotation[:, 0]
    to_target = target - pose.position
    cos = float(sight @ to_target / np.linalg.norm(to_target))
    return math.acos(min(1.0, max(-1.0, cos)))


@pytest.fixture(scope="module")
def jaco2() -> RobotModel:
    return RobotModel.load("jaco2")


def _drifting_hand(t: float) -> np.ndarray:
    """2 s at 120 Hz: the hand drifting 0.1 m/s sideways and 0.05 m/s down."""
    return np.array([0.75, -0.1 + 0.1 * t, 1.1 - 0.05 * t])


def test_tracking_goals_stay_within_the_tracking_tolerance_of_the_target(jaco2):
    ctrl = GazeController(jaco2, ik=IKConfig(goal_deadband=0.0))  # every move re-solved
    loose = IKConfig().tracking_tolerance
    errors = []
    for i in range(240):
        t = i / 120
        state = ctrl.update(t, _drifting_hand(t))
        if i > 0:
            errors.append(_head_error(jaco2, state.head_goal, _drifting_hand(t)))
    assert max(errors) <= loose + 1e-6


@pytest.mark.parametrize("name", ["jaco2", "sawyer"])
def test_within_the_goal_deadband_the_head_goal_is_kept_and_the_eyes_stay_exact(
    name, monkeypatch
):
    import gazebot.core.kinematics.gaze_controller as controller

    robot = RobotModel.load(name)
    cfg = IKConfig()
    solves = []
    solve = controller.solve_head
    monkeypatch.setattr(controller, "solve_head",
                        lambda *a, **k: solves.append(1) or solve(*a, **k))
    ctrl = GazeController(robot)
    exact = GazeController(robot, ik=IKConfig(goal_deadband=0.0))
    goal_errors, residuals = [], []
    for i in range(240):
        t = i / 120
        state = ctrl.update(t, _drifting_hand(t))
        reference = exact.update(t, _drifting_hand(t))
        if reference.residual <= cfg.tolerance:  # where the eyes alone can be exact
            residuals.append(state.residual)
        goal_errors.append(_head_error(robot, state.head_goal, _drifting_hand(t)))
        if name == "jaco2" and i > 0:  # Sawyer's head cannot tilt: its goal misses in pitch
            assert goal_errors[-1] <= cfg.goal_deadband + cfg.tracking_tolerance + 1e-6
    assert len(residuals) > 100 and max(residuals) <= cfg.tolerance
    # The hand moves ~0.05 deg per tick: most ticks keep the goal instead of solving (the
    # reference re-solved all 240).
    assert len(solves) - 240 < 120


def test_with_the_eyes_at_their_range_the_goal_deadband_still_keeps_the_head_goal(monkeypatch):
    """Sawyer cannot tilt its head and its eyes pitch at most 45 deg down: a hand this low is
    beyond their reach. Moving inside the deadband it keeps the head goal (no solve); every
    command stays finite and within the limits, and the gaze misses it by at most the
    deadband more than with the goal re-solved every tick. Leaving the deadband re-solves."""
    import gazebot.core.kinematics.gaze_controller as controller

    robot = RobotModel.load("sawyer")
    cfg = IKConfig()
    ctrl = GazeController(robot)
    exact = GazeController(robot, ik=IKConfig(goal_deadband=0.0))
    hand = np.array([0.6, 0.15, 0.6])
    for i in range(150):  # the gaze shift to the hand lands
        settled = ctrl.update(i / 120, hand)
        exact.update(i / 120, hand)
    assert settled.eyes_saturated and settled.residual > 0.1

    solves = []
    solve = controller.solve_head
    monkeypatch.setattr(controller, "solve_head",
                        lambda *a, **k: solves.append(1) or solve(*a, **k))
    lo, hi = robot.lower, robot.upper
    for i in range(150, 158):  # 0.25 mm per tick sideways: 2 mm ~ 0.2 deg from the head
        moved = hand + np.array([0.0, 0.00025 * (i - 149), 0.0])
        state = ctrl.update(i / 120, moved)
        assert solves == []
        reference = exact.update(i / 120, moved)  # solves every tick
        solves.clear()
        assert state.eyes_saturated
        assert state.head_goal == settled.head_goal
        head = robot.head_vector(state.head)
        assert np.all(np.isfinite(head)) and np.all((lo <= head) & (head <= hi))
        assert math.isfinite(state.eye_yaw) and math.isfinite(state.eye_pitch)
        assert robot.eyes.clip(state.eye_yaw, state.eye_pitch)[:2] == (
            state.eye_yaw, state.eye_pitch)
        assert state.residual <= reference.residual + cfg.goal_deadband
    for i in range(158, 180):  # on to 8 mm (~0.8 deg): out of the deadband
        state = ctrl.update(i / 120, hand + np.array([0.0, 0.00025 * (i - 149) * 4, 0.0]))
    assert solves and state.head_goal != settled.head_goal


def test_fixed_eyes_get_no_goal_deadband():
    from gazebot.core.kinematics.robot_config import with_gaze_mode

    robot = RobotModel.load(with_gaze_mode("jaco2", "head-only"))
    ctrl = GazeController(robot)
    assert ctrl.ik.goal_deadband > 0.0
    for i in range(240):
        t = i / 120
        state = ctrl.update(t, _drifting_hand(t))
        if i > 0:  # the head alone points: every move is re-solved
            assert _head_error(robot, state.head_goal, _drifting_hand(t)) <= (
                IKConfig().tracking_tolerance + 1e-6
            )


def test_the_goal_deadband_is_a_robot_yaml_setting_in_degrees():
    from gazebot.core.kinematics.robot_config import IKSettings

    assert IKConfig.from_settings(IKSettings(goal_deadband_deg=1.0)).goal_deadband == (
        pytest.approx(math.radians(1.0))
    )
    assert IKConfig.from_settings(IKSettings(goal_deadband_deg=0.0)).goal_deadband == 0.0
    sawyer = RobotModel.load("sawyer")
    assert GazeController(sawyer).ik.goal_deadband == pytest.approx(math.radians(0.25))


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
    from gazebot.core.kinematics import solve_ik

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

    from gazebot.core.config import ConfigError, configs_dir

    mjcf = tmp_path / "empty.xml"
    mjcf.write_text("<mujoco><worldbody/></mujoco>")
    cfg = yaml.safe_load((configs_dir() / "robots" / "jaco2.yaml").read_text())
    cfg["mjcf"] = str(mjcf)
    path = tmp_path / "broken.yaml"
    path.write_text(yaml.safe_dump(cfg))
    with pytest.raises(ConfigError) as err:
        RobotModel.load(path)
    assert "empty.xml" in str(err.value)
