"""A robot described by its own URDF: limits from the model, a gaze frame at a link offset,
``package://`` URIs, one-line errors for what the model lacks, and eyes that are joints of the
model driven by the gaze controller within their limits."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from gazebot.core.config import ConfigError
from gazebot.core.kinematics import GazeController, RobotModel
from gazebot.core.kinematics.robot_config import with_package_path
from tests.core.kinematics.eyehead import write_robot


@pytest.fixture
def eyehead(tmp_path) -> RobotModel:
    return RobotModel.load(write_robot(tmp_path))


def test_limits_come_from_the_urdf(eyehead):
    assert eyehead.model_kind == "urdf"
    np.testing.assert_allclose(eyehead.lower, [-1.5, -0.5])
    np.testing.assert_allclose(eyehead.upper, [1.5, 0.8])
    np.testing.assert_allclose(eyehead.velocity_limits, [3.0, 2.5])
    # Eye ranges and speed from the eye joints: the pans' common range, the shared tilt's.
    assert eyehead.eye_yaw_range == pytest.approx((-0.6, 0.6))
    assert eyehead.eye_pitch_range == pytest.approx((-0.4, 0.5))
    assert eyehead.eye_velocity_limit == pytest.approx(8.0)


def test_the_gaze_frame_sits_at_its_offset_from_the_link(eyehead):
    pose = eyehead.gaze_pose(np.zeros(2))
    np.testing.assert_allclose(pose.position, [0.02 + 0.09, 0.0, 1.2 + 0.08 + 0.05], atol=1e-12)
    np.testing.assert_allclose(pose.rotation, np.eye(3), atol=1e-12)
    pose = eyehead.gaze_pose(np.array([0.0, 0.5]))  # tilting down turns +x downward
    assert pose.line_of_sight[2] == pytest.approx(-math.sin(0.5))


def test_a_yaml_velocity_overrides_the_urdf(tmp_path):
    path = write_robot(tmp_path, extra="head_velocity_limits_deg_s: {head_pan: 45.0}\n")
    robot = RobotModel.load(path)
    assert robot.velocity_limits[0] == pytest.approx(math.radians(45.0))


@pytest.mark.parametrize("velocity", ["0", None])
def test_a_head_joint_without_a_velocity_limit_is_an_error_naming_file_and_field(
    tmp_path, velocity
):
    path = write_robot(tmp_path, pan_velocity=velocity or "3.0")
    urdf = tmp_path / "eyehead.urdf"
    if velocity is None:  # no velocity attribute at all (urdfdom alone would refuse the file)
        urdf.write_text(urdf.read_text().replace(' velocity="3.0"', ""))
    with pytest.raises(ConfigError) as err:
        RobotModel.load(path)
    message = str(err.value)
    assert str(urdf) in message and "head_velocity_limits_deg_s.head_pan" in message
    assert "\n" not in message
    # With the override the same file loads.
    path.write_text(path.read_text() + "head_velocity_limits_deg_s: {head_pan: 90.0}\n")
    assert RobotModel.load(path).velocity_limits[0] == pytest.approx(math.radians(90.0))


def test_a_head_joint_without_position_limits_is_an_error(tmp_path):
    path = write_robot(tmp_path)
    urdf = tmp_path / "eyehead.urdf"
    text = urdf.read_text().replace(
        '<limit lower="-0.5" upper="0.8" effort="5" velocity="2.5"/>', ""
    )
    urdf.write_text(text)
    with pytest.raises(ConfigError, match="head_tilt.*position limits"):
        RobotModel.load(path)


def test_package_uris_resolve_from_the_package_path(tmp_path, monkeypatch):
    package = tmp_path / "share" / "eyehead_description" / "urdf"
    package.mkdir(parents=True)
    write_robot(package)
    yaml = write_robot(tmp_path, urdf_ref="package://eyehead_description/urdf/eyehead.urdf")
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    with pytest.raises(ConfigError):
        RobotModel.load(yaml)
    config = with_package_path(yaml, (str(tmp_path / "share"),))
    assert Path(config.urdf) == (package / "eyehead.urdf").resolve()
    assert RobotModel.load(config).head_joints == ["head_pan", "head_tilt"]
    # ROS_PACKAGE_PATH may name the package folder itself.
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "share" / "eyehead_description"))
    assert RobotModel.load(yaml).model_kind == "urdf"


def eye_sight(robot: RobotModel, head: dict[str, float], eyes: dict[str, float]) -> list:
    """Each eye link's +x (base frame) with the head and eye joints set in the full model."""
    model = robot.full_model
    data = model.createData()
    q = pin.neutral(model)
    for name, value in {**head, **eyes}.items():
        q[model.joints[model.getJointId(name)].idx_q] = value
    pin.framesForwardKinematics(model, data, q)
    return [data.oMf[model.getFrameId(link)].rotation[:, 0] for link in ("left_eye", "right_eye")]


def angle(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return math.atan2(np.linalg.norm(np.cross(a, b)), float(a @ b))


def test_eye_joints_share_the_gaze_shift_and_stay_in_their_limits(eyehead):
    ctl = GazeController(eyehead)
    dt = 1.0 / 100.0
    targets = [(0.0, [1.5, 0.0, 1.33]), (1.5, [1.0, 0.9, 1.6]), (3.5, [0.8, -0.4, 0.8])]
    lower = {n: eyehead.full_model.lowerPositionLimit[eyehead.full_model.joints[
        eyehead.full_model.getJointId(n)].idx_q] for n in eyehead.eye_joints}
    upper = {n: eyehead.full_model.upperPositionLimit[eyehead.full_model.joints[
        eyehead.full_model.getJointId(n)].idx_q] for n in eyehead.eye_joints}
    previous = None
    led = settled = 0
    for k in range(int(5.5 / dt) + 1):
        t = k * dt
        start, target = max((s, p) for s, p in targets if s <= t + 1e-9)
        state = ctl.update(t, np.array(target))
        eyes = eyehead.eye_joint_positions(state.eye_yaw, state.eye_pitch)
        for name, value in eyes.items():
            assert lower[name] - 1e-12 <= value <= upper[name] + 1e-12
        if previous is not None:  # the eye joints' speed limit (8 rad/s, the tilt's)
            step = max(abs(eyes[n] - previous[n]) for n in eyes)
            assert step <= eyehead.eye_velocity_limit * dt * 1.001 + 1e-9
        previous = eyes
        origin = eyehead.gaze_pose(eyehead.head_vector(state.head)).position
        misses = [angle(s, np.array(target) - origin) for s in eye_sight(eyehead, state.head, eyes)]
        if start > 0.0 and abs(t - (start + 0.2)) < dt / 2:
            # 0.2 s into a shift the eyes have saccaded (the neck is still turning): they take
            # a share of the shift, the gaze is much closer than the head's line of sight alone.
            assert max(abs(eyes["left_eye_pan"]), abs(eyes["eye_tilt"])) > math.radians(5.0)
            still = eye_sight(eyehead, state.head, dict.fromkeys(eyes, 0.0))
            head_miss = angle(still[0], np.array(target) - origin)
            assert max(misses) < head_miss - math.radians(5.0)
            led += 1
        if t - start > 1.5:
            # Settled: the head took the shift, the eyes are back near centre, on target.
            assert max(misses) < math.radians(0.5)
            assert max(abs(v) for v in eyes.values()) < math.radians(1.0)
            settled += 1
    assert led == 2 and settled > 50


def test_eye_joints_must_turn_about_the_gaze_frame_axes(tmp_path):
    path = write_robot(tmp_path)
    path.write_text(path.read_text().replace(
        "eye_joints: {yaw: [left_eye_pan, right_eye_pan], pitch: [eye_tilt]}",
        "eye_joints: {yaw: [eye_tilt], pitch: [left_eye_pan]}"))
    with pytest.raises(ConfigError, match="eye_joints"):
        RobotModel.load(path)


@pytest.mark.parametrize(
    ("yaw_deg", "pitch_deg"), [(20.0, 0.0), (0.0, -15.0), (-25.0, 20.0), (30.0, 22.0)]
)
def test_eye_joint_positions_point_each_eye_along_the_eye_direction(eyehead, yaw_deg, pitch_deg):
    from gazebot.core.kinematics import eye_direction

    yaw, pitch = math.radians(yaw_deg), math.radians(pitch_deg)
    head = {"head_pan": 0.3, "head_tilt": 0.2}
    eyes = eyehead.eye_joint_positions(yaw, pitch)
    pose = eyehead.gaze_pose(eyehead.head_vector(head))
    want = pose.rotation @ eye_direction(yaw, pitch)
    for sight in eye_sight(eyehead, head, eyes):
        assert angle(sight, want) < 1e-9
