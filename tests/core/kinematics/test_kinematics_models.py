"""The robot MJCF files and YAMLs: what the simulation, the eye renderer and the IK rely on."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from gazebot.core.config import ConfigError
from gazebot.core.kinematics import RobotModel, load_robot_config
from gazebot.core.kinematics.robot_config import resolve_mjcf

ROBOTS = ["sawyer", "jaco2"]


@pytest.fixture(scope="module", params=ROBOTS)
def robot(request: pytest.FixtureRequest) -> RobotModel:
    return RobotModel.load(request.param)


@pytest.fixture(scope="module")
def mj(robot: RobotModel) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(robot.mjcf_path))


def _random_configuration(mj: mujoco.MjModel, rng: np.random.Generator) -> np.ndarray:
    qpos = np.zeros(mj.nq)
    for j in range(mj.njnt):
        lo, hi = mj.jnt_range[j]
        qpos[mj.jnt_qposadr[j]] = rng.uniform(lo, hi)
    return qpos


def test_mujoco_and_pinocchio_agree_on_gaze_and_gripper_sites(robot, mj):
    full = pin.buildModelFromMJCF(str(robot.mjcf_path))
    pdata = full.createData()
    data = mujoco.MjData(mj)
    rng = np.random.default_rng(3)
    assert full.nq == mj.nq, "Pinocchio must see every MuJoCo joint (one kinematic tree)"
    for _ in range(25):
        data.qpos[:] = _random_configuration(mj, rng)
        mujoco.mj_kinematics(mj, data)
        q = np.zeros(full.nq)
        for j in range(1, full.njoints):
            q[full.joints[j].idx_q] = data.qpos[mj.joint(full.names[j]).qposadr[0]]
        pin.framesForwardKinematics(full, pdata, q)
        for site in ("gaze", "gripper"):
            M = pdata.oMf[full.getFrameId(site, pin.FrameType.OP_FRAME)]
            np.testing.assert_allclose(M.translation, data.site(site).xpos, atol=1e-9)
            np.testing.assert_allclose(M.rotation, data.site(site).xmat.reshape(3, 3), atol=1e-9)


def test_reduced_head_model_matches_mujoco_gaze_pose(robot, mj):
    """The IK's reduced model (head + carrying arm joints, rest locked) is the same kinematics."""
    data = mujoco.MjData(mj)
    rng = np.random.default_rng(4)
    for _ in range(10):
        q = rng.uniform(robot.lower, robot.upper)
        data.qpos[:] = 0.0
        for name, value in robot.arm_home.items():
            data.qpos[mj.joint(name).qposadr[0]] = value
        for name, value in robot.head_dict(q).items():
            data.qpos[mj.joint(name).qposadr[0]] = value
        mujoco.mj_kinematics(mj, data)
        pose = robot.gaze_pose(q)
        np.testing.assert_allclose(pose.position, data.site("gaze").xpos, atol=1e-9)
        np.testing.assert_allclose(pose.rotation, data.site("gaze").xmat.reshape(3, 3), atol=1e-9)


def test_every_robot_joint_has_a_position_actuator_with_its_name(robot, mj):
    for name in robot.head_joints + robot.arm_joints:
        act = mj.actuator(name)
        assert mj.actuator_trntype[act.id] == mujoco.mjtTrn.mjTRN_JOINT
        assert mj.actuator_trnid[act.id, 0] == mj.joint(name).id
        # position actuator: force = kp * (ctrl - q) - kv * qdot
        assert mj.actuator_biastype[act.id] == mujoco.mjtBias.mjBIAS_AFFINE
        kp = mj.actuator_gainprm[act.id, 0]
        assert kp > 0 and mj.actuator_biasprm[act.id, 1] == pytest.approx(-kp)
        np.testing.assert_allclose(mj.actuator_ctrlrange[act.id], mj.jnt_range[mj.joint(name).id])


def test_gripper_actuator_closes_the_fingers_from_0_open_to_1_closed(robot, mj):
    act = mj.actuator(robot.config.gripper_actuator)
    np.testing.assert_allclose(mj.actuator_ctrlrange[act.id], [0.0, 1.0])
    data = mujoco.MjData(mj)
    key = mj.key("home").id
    gaps = []
    for ctrl in (0.0, 1.0):
        mujoco.mj_resetDataKeyframe(mj, data, key)
        data.ctrl[act.id] = ctrl
        for _ in range(500):
            mujoco.mj_step(mj, data)
        fingers = [g for g in range(mj.ngeom) if "finger" in (mj.geom(g).name or "")]
        centers = np.array([data.geom_xpos[g] for g in fingers])
        gaps.append(float(np.max(np.linalg.norm(centers - centers.mean(axis=0), axis=1))))
    assert gaps[1] < gaps[0] - 0.01, (
        f"fingers did not close: spread open {gaps[0]}, closed {gaps[1]}"
    )


def test_display_box_material_and_texture_follow_the_contract(robot, mj):
    geom = mj.geom("display")
    assert mj.geom_type[geom.id] == mujoco.mjtGeom.mjGEOM_BOX
    mat = mj.material("display")
    assert mj.geom_matid[geom.id] == mat.id
    tex = mj.texture("display")
    assert mj.tex_type[tex.id] == mujoco.mjtTexture.mjTEXTURE_2D
    rgb_role = int(mujoco.mjtTextureRole.mjTEXROLE_RGB)
    assert mj.mat_texid[mat.id, rgb_role] == tex.id
    assert mj.tex_nchannel[tex.id] == 3
    disp = robot.config.display
    assert mj.tex_width[tex.id] / mj.tex_height[tex.id] == pytest.approx(
        disp.width_px / disp.height_px, rel=0.01
    )
    # the screen face matches the panel's aspect and the stated diagonal
    width, height = 2 * mj.geom_size[geom.id, 1], 2 * mj.geom_size[geom.id, 2]
    assert width / height == pytest.approx(disp.width_px / disp.height_px, rel=0.01)
    assert math.hypot(width, height) / 0.0254 == pytest.approx(disp.diagonal_in, rel=0.02)


def test_gaze_site_looks_forward_with_display_up_and_sits_on_the_screen(robot, mj):
    data = mujoco.MjData(mj)
    mujoco.mj_kinematics(mj, data)
    R = data.site("gaze").xmat.reshape(3, 3)
    np.testing.assert_allclose(R[:, 0], [1, 0, 0], atol=1e-9)  # robot faces +x
    np.testing.assert_allclose(R[:, 2], [0, 0, 1], atol=1e-9)  # display up
    geom = mj.geom("display")
    face_center = (
        data.geom_xpos[geom.id]
        + data.geom_xmat[geom.id].reshape(3, 3)[:, 0] * (mj.geom_size[geom.id, 0])
    )
    np.testing.assert_allclose(data.site("gaze").xpos, face_center, atol=1e-6)


def test_robot_file_has_no_lights_or_floor_the_scene_adds_them(mj):
    assert mj.nlight == 0
    planes = [g for g in range(mj.ngeom) if mj.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE]
    assert planes == []


def test_yaml_poses_are_within_limits_and_the_handover_pose_reaches_the_handover_point(robot, mj):
    data = mujoco.MjData(mj)
    for pose in (robot.arm_home, robot.arm_handover):
        for name, value in pose.items():
            lo, hi = mj.jnt_range[mj.joint(name).id]
            assert lo <= value <= hi, f"{name}={value} outside [{lo}, {hi}]"
    for name, value in robot.arm_handover.items():
        data.qpos[mj.joint(name).qposadr[0]] = value
    mujoco.mj_kinematics(mj, data)
    grip = data.site("gripper").xpos
    np.testing.assert_allclose(grip, robot.points["handover_location"], atol=0.01)
    # gripper tool axis (site +z) points at the giver (+x)
    assert data.site("gripper").xmat.reshape(3, 3)[:, 2] @ np.array([1.0, 0, 0]) > 0.99
    # a handover location a standing giver can reach: 0.5-0.7 m in front, ~1 m high
    assert 0.5 <= grip[0] <= 0.7 and 0.9 <= grip[2] <= 1.1


def test_position_actuators_hold_the_home_pose_under_gravity(robot, mj):
    data = mujoco.MjData(mj)
    mujoco.mj_resetDataKeyframe(mj, data, mj.key("home").id)
    for _ in range(1000):
        mujoco.mj_step(mj, data)
    for name, value in robot.arm_home.items():
        assert abs(data.qpos[mj.joint(name).qposadr[0]] - value) < 0.02, name
    assert data.ncon == 0, "robot geoms touch each other at home"


def test_keyframes_match_the_yaml_poses(robot, mj):
    data = mujoco.MjData(mj)
    for key, pose in (("home", robot.arm_home), ("handover", robot.arm_handover)):
        mujoco.mj_resetDataKeyframe(mj, data, mj.key(key).id)
        for name, value in pose.items():
            assert data.qpos[mj.joint(name).qposadr[0]] == pytest.approx(value, abs=1e-3)


def test_display_image_appears_upright_and_unmirrored_to_a_person_facing_the_robot(robot, mj):
    """Write an asymmetric image into the display texture (as the simulation does) and render the
    head from a camera in front of it: the top-left red block must appear top-left."""
    tex = mj.texture("display")
    h, w = int(mj.tex_height[tex.id]), int(mj.tex_width[tex.id])
    img = np.zeros((h, w, 3), np.uint8)
    img[: h // 2, : w // 2] = (255, 0, 0)  # top-left: red
    img[: h // 2, w // 2 :] = (0, 255, 0)  # top-right: green
    img[h // 2 :, :] = (0, 0, 255)  # bottom: blue
    adr = int(mj.tex_adr[tex.id])
    mj.tex_data[adr : adr + img.size] = img.reshape(-1)
    data = mujoco.MjData(mj)
    mujoco.mj_kinematics(mj, data)
    try:
        renderer = mujoco.Renderer(mj, 240, 320)
    except Exception as exc:  # no off-screen GL on this machine
        pytest.skip(f"off-screen rendering unavailable: {exc}")
    try:
        cam = mujoco.MjvCamera()
        cam.lookat[:] = data.site("gaze").xpos
        cam.distance = 0.12 if robot.name == "jaco2" else 0.18
        cam.azimuth, cam.elevation = 180.0, 0.0  # in front, looking along -x
        renderer.update_scene(data, cam)
        frame = renderer.render().astype(int)
    finally:
        renderer.close()
    H, W = frame.shape[:2]

    def dominant(y: float, x: float) -> int:
        patch = frame[int(y * H) - 3 : int(y * H) + 3, int(x * W) - 3 : int(x * W) + 3]
        return int(np.argmax(patch.reshape(-1, 3).mean(axis=0)))

    assert dominant(0.35, 0.35) == 0, "top-left of the image should be red"
    assert dominant(0.35, 0.65) == 1, "top-right of the image should be green"
    assert dominant(0.65, 0.5) == 2, "bottom of the image should be blue"


def test_unknown_robot_and_malformed_yaml_give_clear_errors(tmp_path: Path):
    with pytest.raises(FileNotFoundError, match="unknown robot"):
        RobotModel.load("no-such-robot")
    bad = tmp_path / "bad.yaml"
    config, path = load_robot_config("sawyer")
    text = path.read_text().replace("yaw_range_deg: [-40.0, 40.0]", "yaw_range_deg: [10.0, 5.0]")
    bad.write_text(text)
    with pytest.raises(ConfigError, match="yaw_range_deg"):
        RobotModel.load(bad)
    missing = tmp_path / "missing.yaml"
    missing.write_text(path.read_text().replace("mjcf: sawyer.xml", "mjcf: nowhere.xml"))
    with pytest.raises(ConfigError, match="mjcf"):
        RobotModel.load(missing)
    assert resolve_mjcf(config, path).name == "sawyer.xml"


def test_joint_space_move_from_home_to_handover_is_short_and_collision_free(robot):
    """The simulation moves the arm between the two YAML poses in joint space."""
    home = np.array([robot.arm_home[j] for j in robot.arm_joints])
    handover = np.array([robot.arm_handover[j] for j in robot.arm_joints])
    assert np.all(np.abs(handover - home) < math.pi), "no joint swings half a turn"
    mj = mujoco.MjModel.from_xml_path(str(robot.mjcf_path))
    mj.geom_contype[:] = 1  # let every robot geom collide with every other for this check
    mj.geom_conaffinity[:] = 1
    data = mujoco.MjData(mj)
    adr = [mj.joint(j).qposadr[0] for j in robot.arm_joints]
    for s in np.linspace(0.0, 1.0, 41):
        data.qpos[:] = 0.0
        data.qpos[adr] = home + (handover - home) * s
        mujoco.mj_forward(mj, data)
        touching = {
            (mj.geom(c.geom1).name, mj.geom(c.geom2).name) for c in data.contact[: data.ncon]
        }
        assert not touching, f"at {s:.2f} of the move: {touching}"


def test_kinematics_calls_give_the_same_result_in_any_order():
    """The model's Pinocchio data is shared scratch space: no call may depend on the one before."""
    robot = RobotModel.load("sawyer")
    qa = (robot.rest + 0.3 * (robot.upper - robot.rest)).tolist()
    qb = (robot.rest + 0.3 * (robot.lower - robot.rest)).tolist()
    fresh = RobotModel.load("sawyer")
    want_a = fresh.gaze_jacobian_rows(qa)
    want_b = fresh.gaze_jacobian_rows(qb)
    robot.gaze_frame_lists(qb)  # data now holds qb's kinematics
    np.testing.assert_allclose(robot.gaze_jacobian_rows(qa), want_a, atol=1e-12)
    robot.gaze_frame_lists(qa)
    robot.gaze_pose(np.array(qb))
    np.testing.assert_allclose(robot.gaze_jacobian_rows(qa), want_a, atol=1e-12)
    robot.gaze_frame_lists(qb)
    np.testing.assert_allclose(robot.gaze_jacobian_rows(qb), want_b, atol=1e-12)
    # A moved arm carrying the head is a different configuration too.
    robot.gaze_frame_lists(qa)
    assert robot.set_arm({robot.passive_joints[0]: 0.7})
    fresh.set_arm({robot.passive_joints[0]: 0.7})
    np.testing.assert_allclose(
        robot.gaze_jacobian_rows(qa), fresh.gaze_jacobian_rows(qa), atol=1e-12
    )
