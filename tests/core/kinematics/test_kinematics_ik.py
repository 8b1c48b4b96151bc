"""Look-at IK: Jacobians, accuracy on reachable targets, clamping, bad input."""

from __future__ import annotations

import functools
import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gazebot.core.kinematics import IKConfig, RobotModel, solve_ik
from gazebot.core.kinematics.look_at import pointing_error

HALF_DEG = math.radians(0.5)


@functools.cache
def _load(name: str) -> RobotModel:
    return RobotModel.load(name)


@pytest.fixture(scope="module")
def sawyer() -> RobotModel:
    return RobotModel.load("sawyer")


@pytest.fixture(scope="module")
def jaco2() -> RobotModel:
    return RobotModel.load("jaco2")


@pytest.mark.parametrize("name", ["sawyer", "jaco2"])
def test_gaze_frame_jacobian_matches_finite_differences(name):
    robot = RobotModel.load(name)
    rng = np.random.default_rng(0)
    h = 1e-6
    for _ in range(10):
        q = rng.uniform(robot.lower + 0.01, robot.upper - 0.01)
        pose, J = robot.gaze_jacobian(q)
        for i in range(robot.n_head):
            dq = np.zeros(robot.n_head)
            dq[i] = h
            plus, minus = robot.gaze_pose(q + dq), robot.gaze_pose(q - dq)
            lin = (plus.position - minus.position) / (2 * h)
            # world angular velocity: log(R+ R-^T) / 2h
            ang = pin.log3(plus.rotation @ minus.rotation.T) / (2 * h)
            np.testing.assert_allclose(J[:3, i], lin, atol=1e-7)
            np.testing.assert_allclose(J[3:, i], ang, atol=1e-7)


@pytest.mark.parametrize("name", ["sawyer", "jaco2"])
def test_pointing_error_jacobian_matches_finite_differences(name):
    robot = RobotModel.load(name)
    rng = np.random.default_rng(1)
    h = 1e-6
    checked = 0
    for _ in range(40):
        q = rng.uniform(robot.lower + 0.01, robot.upper - 0.01)
        target = rng.uniform([-1.0, -1.5, 0.3], [2.0, 1.5, 2.2])
        e, Je = pointing_error(*robot.gaze_jacobian(q), target)
        if abs(e[0]) > 3.0:  # azimuth wraps at +-pi: finite differences are meaningless there
            continue
        for i in range(robot.n_head):
            dq = np.zeros(robot.n_head)
            dq[i] = h
            ep = pointing_error(*robot.gaze_jacobian(q + dq), target)[0]
            em = pointing_error(*robot.gaze_jacobian(q - dq), target)[0]
            np.testing.assert_allclose(Je[:, i], (ep - em) / (2 * h), atol=1e-6)
        checked += 1
    assert checked > 20


def _front_targets() -> list[np.ndarray]:
    """Where a giver's face, hands and the object are: in front of the robot, 0.4-1.6 m away."""
    xs, ys, zs = np.linspace(0.5, 1.6, 4), np.linspace(-0.6, 0.6, 4), np.linspace(0.8, 1.8, 4)
    return [np.array([x, y, z]) for x in xs for y in ys for z in zs]


def test_jaco2_head_alone_points_at_reachable_targets_within_half_a_degree(jaco2):
    for target in _front_targets():
        sol = solve_ik(jaco2, target)
        assert sol.valid and sol.converged, (target, sol.message)
        assert sol.residual < HALF_DEG, (target, math.degrees(sol.residual))
        assert abs(sol.joints["head_roll"]) < 1e-3, "roll does not help pointing: stays upright"


def test_sawyer_eyes_close_what_the_pan_cannot_within_the_eye_range(sawyer):
    hits = 0
    for target in _front_targets():
        sol = solve_ik(sawyer, target)
        assert sol.valid
        if sol.eyes_saturated:
            continue
        hits += 1
        assert sol.total_residual < HALF_DEG, (target, math.degrees(sol.total_residual))
        # Sawyer only pans: the head fixes azimuth, the eyes fix elevation
        assert abs(sol.eye_yaw) < 1e-3
    assert hits > 50


def test_eye_angles_follow_the_convention_left_positive_down_positive(sawyer):
    below = solve_ik(sawyer, [0.6, 0.0, 1.0])  # hand height, display at ~1.4 m
    assert below.eye_pitch > math.radians(20)
    above = solve_ik(sawyer, [1.1, 0.0, 1.8])
    assert above.eye_pitch < -math.radians(10)
    # to the robot's far left the pan saturates at +52 deg: the eyes turn further left
    left = solve_ik(sawyer, [0.3, 1.0, 1.4])
    assert left.clamped and left.joints["head_pan"] == pytest.approx(sawyer.upper[0])
    assert left.eye_yaw > math.radians(10)


@pytest.mark.parametrize("name", ["sawyer", "jaco2"])
@pytest.mark.parametrize(
    "target",
    [[-1.0, 0.0, 1.2], [-0.5, -0.01, 3.0], [0.0, -2.0, 0.0], [0.3, 5.0, 1.0], [0.0, 0.0, -4.0]],
)
def test_unreachable_targets_clamp_to_limits_and_report_without_nan(name, target):
    robot = RobotModel.load(name)
    sol = solve_ik(robot, target)
    assert sol.valid
    assert np.all(np.isfinite(sol.q)) and np.isfinite([sol.residual, sol.total_residual]).all()
    assert np.all(sol.q >= robot.lower) and np.all(sol.q <= robot.upper)
    assert robot.eye_yaw_range[0] <= sol.eye_yaw <= robot.eye_yaw_range[1]
    assert robot.eye_pitch_range[0] <= sol.eye_pitch <= robot.eye_pitch_range[1]
    assert sol.total_residual <= sol.residual + 1e-9
    if sol.total_residual > HALF_DEG:
        assert sol.message, "an off-target solution says why"


def test_target_behind_the_head_still_turns_toward_it(sawyer):
    """Exactly behind is a saddle of the pointing error; the solver must not stay facing away."""
    sol = solve_ik(sawyer, [-1.0, 0.0, 1.4])
    assert abs(sol.joints["head_pan"]) > math.radians(45)


def test_non_finite_target_holds_the_warm_start_and_is_flagged(jaco2):
    q0 = {"head_pan": 0.3, "neck_tilt": 0.1}
    sol = solve_ik(jaco2, [np.nan, 0.0, 1.0], q0=q0)
    assert not sol.valid and "finite" in sol.message
    assert sol.joints["head_pan"] == pytest.approx(0.3) and sol.joints["neck_tilt"] == 0.1
    assert np.all(np.isfinite(sol.q))


def test_target_at_the_gaze_origin_is_flagged_not_solved(jaco2):
    origin = jaco2.gaze_pose(jaco2.rest).position
    sol = solve_ik(jaco2, origin)
    assert not sol.valid and "origin" in sol.message


def test_bad_target_shape_and_unknown_joint_raise_clear_errors(jaco2):
    with pytest.raises(ValueError, match="3D point"):
        solve_ik(jaco2, [1.0, 2.0])
    with pytest.raises(ValueError, match="unknown head joints"):
        solve_ik(jaco2, [1.0, 0.0, 1.0], q0={"elbow": 1.0})


def test_warm_start_needs_fewer_iterations_than_a_cold_start(jaco2):
    face = jaco2.points["face"]
    cold = solve_ik(jaco2, face + [0.0, 0.05, 0.0])
    previous = solve_ik(jaco2, face)
    warm = solve_ik(jaco2, face + [0.0, 0.05, 0.0], q0=previous.q)
    assert warm.iterations < cold.iterations
    assert warm.residual < HALF_DEG


def test_iteration_cap_is_reported_not_hidden(jaco2):
    sol = solve_ik(jaco2, [1.0, -0.8, 1.6], config=IKConfig(max_iterations=1))
    assert not sol.converged and "iteration" in sol.message
    assert np.all(np.isfinite(sol.q))


@settings(max_examples=60, deadline=None)
@given(
    x=st.floats(-3, 3),
    y=st.floats(-3, 3),
    z=st.floats(-1, 4),
    robot_name=st.sampled_from(["sawyer", "jaco2"]),
)
def test_any_target_gives_finite_within_limit_joints(x, y, z, robot_name):
    robot = _load(robot_name)
    sol = solve_ik(robot, [x, y, z])
    assert np.all(np.isfinite(sol.q))
    assert np.all(sol.q >= robot.lower) and np.all(sol.q <= robot.upper)
    if sol.valid:
        assert math.isfinite(sol.total_residual) and math.isfinite(sol.eye_yaw)


@pytest.mark.parametrize("name", ["sawyer", "jaco2"])
def test_the_robot_yamls_ik_block_is_the_solver_settings_of_engine_controller_and_look_at(name):
    from gazebot import GazeEngine
    from gazebot.core.kinematics import GazeController

    robot = RobotModel.load(name)
    from_yaml = IKConfig.from_settings(robot.config.ik)
    assert from_yaml == IKConfig()  # the shipped values are the solver's defaults, exactly
    assert from_yaml.max_iterations == 25 and from_yaml.tolerance == 1e-5
    assert GazeController(robot).ik == from_yaml
    assert GazeEngine.from_config(robot=name, behavior="face-hand-face").gaze.ik == from_yaml


def test_an_ik_setting_in_the_robot_yaml_changes_the_solve(tmp_path):
    import yaml

    from gazebot.core.kinematics import GazeController
    from gazebot.core.kinematics.robot_config import robot_config_path

    data = yaml.safe_load(robot_config_path("jaco2").read_text())
    data["mjcf"] = str((robot_config_path("jaco2").parents[2] / "gazebot/assets/robots"
                        / data["mjcf"]).resolve())
    data["ik"] = {"max_iterations": 1, "max_step_deg": 1.0}
    f = tmp_path / "slow.yaml"
    f.write_text(yaml.safe_dump(data))
    robot = RobotModel.load(f)
    cfg = GazeController(robot).ik
    assert cfg.max_iterations == 1 and cfg.max_step == pytest.approx(np.radians(1.0))
    assert cfg.tolerance == IKConfig().tolerance  # left out: the solver's default
    one_step = solve_ik(robot, [1.0, 0.8, 1.2])
    assert not one_step.converged  # 1 deg in one iteration cannot reach a target 40 deg away
    assert solve_ik(RobotModel.load("jaco2"), [1.0, 0.8, 1.2]).converged


def test_a_bad_ik_setting_names_the_file_and_the_field(tmp_path):
    import yaml

    from gazebot.core.config import ConfigError
    from gazebot.core.kinematics import load_robot_config
    from gazebot.core.kinematics.robot_config import robot_config_path

    data = yaml.safe_load(robot_config_path("sawyer").read_text())
    data["ik"] = {"max_iterations": 0}
    f = tmp_path / "bad.yaml"
    f.write_text(yaml.safe_dump(data))
    with pytest.raises(ConfigError, match=r"bad\.yaml.*ik\.max_iterations"):
        load_robot_config(f)
