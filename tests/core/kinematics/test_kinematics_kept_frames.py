"""What the gaze kinematics keep between calls changes no result: the gaze frame kept for the last
head pose and arm pose, the controller's step and its full state, the head state value."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from gazebot.core.kinematics import GazeController, RobotModel
from gazebot.core.kinematics.gaze_controller import HeadEyeState


@pytest.fixture(scope="module")
def sawyer() -> RobotModel:
    return RobotModel.load("sawyer")


def _fresh_frame(robot: RobotModel, head: list[float]) -> list[list[float]]:
    robot._last_frame = None  # what every call did before the frame was kept
    return robot.gaze_frame_lists(head)


def test_the_kept_gaze_frame_follows_head_and_arm_moves(sawyer):
    robot = RobotModel.load("sawyer")
    for head, arm in [(0.2, None), (0.2, None), (0.2, 0.4), (-0.5, 0.4), (0.2, 0.4), (0.2, -0.1)]:
        if arm is not None:
            robot.set_arm({"right_j0": arm})
        rows = robot.gaze_frame_lists([head])
        pose = robot.gaze_pose(np.array([head]))  # Pinocchio from scratch
        assert np.allclose(np.array(rows)[:, :3], pose.rotation, atol=0, rtol=0)
        assert np.allclose(np.array(rows)[:, 3], pose.position, atol=0, rtol=0)
        assert rows == _fresh_frame(robot, [head])


def test_a_gaze_frame_asked_twice_is_computed_once(sawyer, monkeypatch):
    robot = RobotModel.load("sawyer")
    calls = []
    import pinocchio as pin

    real = pin.forwardKinematics
    monkeypatch.setattr(pin, "forwardKinematics", lambda *a: calls.append(1) or real(*a))
    first = robot.gaze_frame_lists([0.3])
    assert robot.gaze_frame_lists([0.3]) is first and len(calls) == 1
    robot.set_arm({"right_j0": 0.2})  # the arm carries the head: a new frame
    assert robot.gaze_frame_lists([0.3]) != first and len(calls) == 2


def test_controller_states_equal_those_computed_without_the_kept_frame(sawyer, monkeypatch):
    def run(robot: RobotModel) -> list[HeadEyeState]:
        ctrl = GazeController(robot)
        states = []
        for i in range(180):  # a face drifting, the arm turning under the head, a big shift
            t = i / 120
            target = np.array([1.0, -0.3 + 0.4 * t, 1.2 + 0.05 * math.sin(3 * t)])
            if i == 90:
                target = np.array([0.6, 0.5, 0.9])
            arm = {"right_j0": 0.1 * math.sin(2 * t)} if i % 3 == 0 else None
            states.append(ctrl.update(t, target, arm=arm))
        return states

    kept = run(RobotModel.load("sawyer"))
    plain_robot = RobotModel.load("sawyer")
    real = RobotModel.gaze_frame_lists
    monkeypatch.setattr(
        plain_robot, "gaze_frame_lists", lambda q: (setattr(plain_robot, "_last_frame", None),
                                                    real(plain_robot, q))[1]
    )
    plain = run(plain_robot)
    assert kept == plain  # bit for bit: every head, goal, velocity and eye value


def test_head_state_has_every_dataclass_field_and_compares_like_one(sawyer):
    state = GazeController(sawyer).update(0.0, np.array([1.0, 0.2, 1.3]))
    names = {f.name for f in dataclasses.fields(HeadEyeState)}
    assert set(vars(state)) == names
    rebuilt = HeadEyeState(**{n: getattr(state, n) for n in names})
    assert rebuilt == state and repr(rebuilt) == repr(state)
    with pytest.raises(dataclasses.FrozenInstanceError):
        state.eye_yaw = 1.0  # type: ignore[misc]


@pytest.mark.parametrize("name", ["sawyer", "jaco2"])
def test_step_gives_the_floats_of_update(name):
    robot_a, robot_b = RobotModel.load(name), RobotModel.load(name)
    full, bare = GazeController(robot_a), GazeController(robot_b)
    shifts = []
    for i in range(240):  # a drifting hand, a gaze shift, a missing sample, time going back
        t = i / 120 if i != 150 else 100 / 120
        target = np.array([0.9, -0.2 + 0.5 * t, 1.0 + 0.05 * math.sin(4 * t)])
        if i >= 120:
            target = np.array([1.1, 0.4, 1.5])
        if i == 100:
            target = np.full(3, math.nan)
        state = full.update(t, target)
        head, yaw, pitch, residual, shift = bare.step(t, target)
        assert head == list(state.head.values())  # bit for bit, in head_joints order
        assert (yaw, pitch, residual, shift) == (
            state.eye_yaw, state.eye_pitch, state.residual, state.shift_amplitude
        )
        shifts.append(shift)
    assert max(shifts) > 0.0  # the shift at i = 120 went through both


@pytest.mark.parametrize("dtype", [np.float32, np.float16])
def test_eye_residual_of_a_narrow_float_vector_is_computed_in_double(sawyer, dtype):
    v = np.array([1.0, 0.3, -0.2], dtype)
    assert sawyer.eyes.residual(0.1, 0.05, v) == sawyer.eyes.residual(0.1, 0.05, v.astype(float))


@pytest.mark.parametrize("name", ["sawyer", "jaco2"])
def test_a_head_vector_of_the_wrong_length_is_refused_not_truncated(name):
    robot = RobotModel.load(name)
    n = len(robot.head_joints)
    with pytest.raises(ValueError):
        robot.gaze_frame_lists([0.1] * (n + 1))
