"""Gaze modes (seed 6.3: a head with "a static image of two eyes"; 6.4: "robot eye gazes instead of
head gazes"), robots without head joints and eyes without range."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from gazebot.core.config import ConfigError
from gazebot.core.engine import GazeEngine
from gazebot.core.kinematics import (
    GazeController,
    RobotModel,
    load_robot_config,
    solve_ik,
    with_gaze_mode,
)
from gazebot.core.kinematics.robot_config import robot_config_path
from gazebot.core.phases.synthetic import SyntheticOptions, generate

ROBOTS = ["sawyer", "jaco2"]


def _targets(t: float) -> np.ndarray:
    """Face, then a hand sweeping low and to the side: the neck and the eyes both have work."""
    if t < 0.6:
        return np.array([1.1, 0.1, 1.6])
    s = (t - 0.6) / 1.4
    return np.array([0.8, -0.35 + 0.5 * s, 0.85 + 0.1 * s])


def _drive(robot: RobotModel) -> tuple[np.ndarray, np.ndarray]:
    """Head joint and eye angle histories (ticks x joints, ticks x 2) for the target sweep."""
    ctrl = GazeController(robot)
    heads, eyes = [], []
    for k in range(int(2.0 * 120)):
        t = k / 120
        state = ctrl.update(t, _targets(t))
        assert all(math.isfinite(v) for v in state.head.values())
        heads.append([state.head[j] for j in robot.head_joints])
        eyes.append([state.eye_yaw, state.eye_pitch])
    return np.array(heads).reshape(len(heads), -1), np.array(eyes)


@pytest.mark.parametrize("name", ROBOTS)
def test_eyes_only_keeps_every_head_joint_still_while_the_eyes_move(name):
    robot = RobotModel.load(with_gaze_mode(name, "eyes-only"))
    heads, eyes = _drive(robot)
    np.testing.assert_array_equal(heads, np.tile(robot.rest, (len(heads), 1)))
    assert np.ptp(eyes[:, 0]) > math.radians(5) and np.ptp(eyes[:, 1]) > math.radians(5)


@pytest.mark.parametrize("name", ROBOTS)
def test_head_only_keeps_the_eyes_fixed_while_the_head_moves(name):
    robot = RobotModel.load(with_gaze_mode(name, "head-only"))
    heads, eyes = _drive(robot)
    assert np.all(eyes == 0.0)
    assert np.max(np.ptp(heads, axis=0)) > math.radians(10)


@pytest.mark.parametrize("name", ROBOTS)
def test_head_and_eyes_moves_both(name):
    heads, eyes = _drive(RobotModel.load(with_gaze_mode(name, "head-and-eyes")))
    assert np.max(np.ptp(heads, axis=0)) > math.radians(10)
    assert np.max(np.ptp(eyes, axis=0)) > math.radians(2)


def test_the_gaze_mode_is_read_from_the_robot_yaml(tmp_path):
    data = yaml.safe_load(robot_config_path("jaco2").read_text(encoding="utf-8"))
    data["gaze_mode"] = "eyes-only"
    data["mjcf"] = str(RobotModel.load("jaco2").mjcf_path)
    path = tmp_path / "still-jaco.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    robot = RobotModel.load(path)
    assert robot.gaze_mode == "eyes-only" and not robot.head_moves
    data["gaze_mode"] = "neck-only"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    with pytest.raises(ConfigError, match="gaze_mode"):
        RobotModel.load(path)


def test_an_unknown_gaze_mode_is_refused():
    with pytest.raises(ValueError, match="head-only"):
        with_gaze_mode("sawyer", "neck-only")


def _variant(tmp_path, name: str, **changes) -> RobotModel:
    config, path = load_robot_config(name)
    data = config.model_dump()
    data.update(mjcf=str(RobotModel.load(name).mjcf_path), **changes)
    out = tmp_path / f"{name}-variant.yaml"
    out.write_text(yaml.safe_dump(data), encoding="utf-8")
    return RobotModel.load(out)


def test_a_robot_without_head_joints_loads_and_looks_with_its_eyes(tmp_path):
    robot = _variant(
        tmp_path, "sawyer", head_joints=[], head_velocity_limits_deg_s={}, head_rest_deg={}
    )
    assert robot.n_head == 0 and not robot.head_moves
    sol = solve_ik(robot, np.array([1.0, 0.4, 0.9]))
    assert sol.valid and sol.joints == {} and sol.eye_yaw > math.radians(5)
    heads, eyes = _drive(robot)
    assert heads.shape[1] == 0 and np.ptp(eyes[:, 0]) > math.radians(5)


def test_eyes_without_range_load_and_stay_centred(tmp_path):
    robot = _variant(
        tmp_path,
        "jaco2",
        eyes={"yaw_range_deg": [0.0, 0.0], "pitch_range_deg": [0.0, 0.0]},
    )
    heads, eyes = _drive(robot)
    assert np.all(eyes == 0.0) and np.max(np.ptp(heads, axis=0)) > math.radians(10)


def test_eyes_only_through_the_engine_on_a_handover():
    """The whole engine (phases, behavior, controller) in eyes-only mode: the head never moves."""
    rec = generate(3, SyntheticOptions(rate=120.0, posture="standing"))
    engine = GazeEngine.from_config(with_gaze_mode("jaco2", "eyes-only"), "face-hand-face")
    rest = engine.robot.head_dict(engine.robot.rest)
    yaws = []
    for frame in rec.trajectory.frames():
        cmd = engine.step(frame)
        assert cmd.head == rest
        yaws.append(cmd.eye_yaw)
    assert np.ptp(yaws) > math.radians(2)


@pytest.mark.parametrize(
    "argv",
    [
        ["demo"],
        ["render", "video", "--behavior", "hand", "--out", "x.mp4"],
        ["run"],
        ["sim", "--headless"],
    ],
)
def test_every_consumer_command_takes_a_gaze_mode(argv):
    from gazebot.apps.cli import build_parser
    from gazebot.apps.cli.demo import default_robot

    args = build_parser().parse_args([*argv, "--gaze-mode", "eyes-only"])
    assert args.gaze_mode == "eyes-only"
    # the demo's robot follows its controller (the learned gps reach runs on the panda)
    name = default_robot(args) if argv[0] == "demo" else args.robot
    robot = with_gaze_mode(name, args.gaze_mode)
    assert RobotModel.load(robot).gaze_mode == "eyes-only"
    assert build_parser().parse_args(argv).gaze_mode is None  # default: the robot YAML's


def test_a_bad_gaze_mode_on_the_command_line_is_a_clear_error(capsys, tmp_path):
    from gazebot.apps.cli import main

    assert main(["demo", "--gaze-mode", "neck-only", "--out", str(tmp_path / "demo")]) == 2
    err = capsys.readouterr().err
    assert "head-and-eyes" in err and "neck-only" in err
