"""``gazebot run --robot-description``: the robot's URDF and its camera frame come from a
running stack (an rmw_zenoh peer written from rmw_zenoh's source with zenoh-ext and rosbags,
publishing latched ``/robot_description`` and ``/tf_static`` before gazebot starts); tracking
sent in the camera frame is aimed at, checked through the URDF's forward kinematics computed
here with Pinocchio; tracking in a frame with no transform is a counted drop with one warning."""

from __future__ import annotations

import argparse
import json
import logging
import math
import threading
import time

import numpy as np
import pinocchio as pin
import pytest
from test_drivers_latched import JAZZY, STRING, TF, RmwZenohPeer

pytestmark = pytest.mark.zenoh

HEAD_URDF = """<robot name="stackhead">
  <link name="base_link"/><link name="torso"/><link name="neck"/><link name="head"/>
  <link name="camera_optical"/>
  <joint name="torso_fixed" type="fixed"><parent link="base_link"/><child link="torso"/>
    <origin xyz="0 0 0.8"/></joint>
  <joint name="head_pan" type="revolute"><parent link="torso"/><child link="neck"/>
    <origin xyz="0 0 0.4"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="1.5" effort="5" velocity="3.0"/></joint>
  <joint name="head_tilt" type="revolute"><parent link="neck"/><child link="head"/>
    <origin xyz="0.02 0 0.08"/><axis xyz="0 1 0"/>
    <limit lower="-0.8" upper="0.8" effort="5" velocity="3.0"/></joint>
  <joint name="camera_fixed" type="fixed"><parent link="head"/><child link="camera_optical"/>
    <origin xyz="0.1 0 0.1" rpy="-1.5707963 0 -1.5707963"/></joint>
</robot>
"""

#: The few lines a URDF does not say; no urdf:/mjcf: (the URDF comes from the stack).
ROBOT_YAML = """name: stackhead
base_frame: base_link
head_joints: [head_pan, head_tilt]
gaze_frame: {link: head, xyz: [0.09, 0.0, 0.05]}
ik: {goal_deadband_deg: 0.0, tolerance_deg: 0.05}
points: {face: [1.2, 0.0, 1.6], handover_location: [0.6, 0.0, 0.9], rest: [1.5, 0.5, 1.3]}
"""

#: The stack's static camera (a chest camera, not in the URDF): base_link -> chest_camera,
#: 0.15 m forward, 1.1 m up, optical axes (z forward, x right, y down).
CAMERA_XYZ = np.array([0.15, 0.0, 1.1])
CAMERA_XYZW = (-0.5, 0.5, -0.5, 0.5)
CAMERA_R = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])  # columns x, y, z
FACE_IN_CAMERA = np.array([0.25, -0.2, 1.0])  # 0.25 m right, 0.2 m up, 1 m ahead


def _tf_static(stamp_s: int):
    T = JAZZY.types
    x, y, z, w = CAMERA_XYZW
    return T[TF](transforms=[T["geometry_msgs/msg/TransformStamped"](
        header=T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=stamp_s,
                                                                             nanosec=0),
                                        frame_id="base_link"),
        child_frame_id="chest_camera",
        transform=T["geometry_msgs/msg/Transform"](
            translation=T["geometry_msgs/msg/Vector3"](x=float(CAMERA_XYZ[0]), y=0.0,
                                                       z=float(CAMERA_XYZ[2])),
            rotation=T["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w)))])


def _point(frame: str, t: float, p: np.ndarray):
    T = JAZZY.types
    sec = int(t)
    return T["geometry_msgs/msg/PointStamped"](
        header=T["std_msgs/msg/Header"](
            stamp=T["builtin_interfaces/msg/Time"](sec=sec, nanosec=int(round((t - sec) * 1e9))),
            frame_id=frame),
        point=T["geometry_msgs/msg/Point"](x=float(p[0]), y=float(p[1]), z=float(p[2])))


def _parser() -> argparse.ArgumentParser:
    from gazebot.apps.cli import run as run_cli

    parser = argparse.ArgumentParser(prog="gazebot")
    run_cli.register(parser.add_subparsers())
    return parser


def test_run_takes_urdf_and_camera_frame_from_the_stack_and_aims_at_tracking_in_it(
        bus, tmp_path, capsys, caplog):
    robot_yaml = tmp_path / "stackhead.yaml"
    robot_yaml.write_text(ROBOT_YAML)
    session = bus.listener()
    peer = RmwZenohPeer(session)
    desc = peer.latched_publisher("/robot_description", STRING)
    static = peer.latched_publisher("/tf_static", TF)
    peer.put(desc, STRING, JAZZY.types[STRING](data=HEAD_URDF))
    peer.put(static, TF, _tf_static(1))

    ns = bus.names.namespace.strip("/")
    point_type = "geometry_msgs/msg/PointStamped"
    # The tracker: an announced ROS node (the engine takes tracking only from such publishers).
    from gazebot.io.drivers.rmw.node import RosNode

    tracker = RosNode(bus.connector(), bus.names, "mocap")
    bus.closers.append(tracker.close)
    face_pub = tracker.publisher("tracking/giver_face", point_type)
    hand_pub = tracker.publisher("tracking/giver_hand", point_type)
    tracker.announce()
    commands: list = []
    targets: list = []
    session.declare_subscriber(
        f"0/{ns}/head/command/*/*",
        lambda s: commands.append(JAZZY.deserialize_cdr(
            s.payload.to_bytes(), "trajectory_msgs/msg/JointTrajectory")))
    session.declare_subscriber(
        f"0/{ns}/gaze_target/*/*",
        lambda s: targets.append(JAZZY.deserialize_cdr(s.payload.to_bytes(), point_type)))

    stop = threading.Event()

    def track() -> None:  # 50 Hz, stamps on the stack's clock (from 100 s)
        t = 100.0
        while not stop.is_set():
            face_pub.publish(_point("chest_camera", t, FACE_IN_CAMERA))
            hand_pub.publish(_point("ghost_frame", t, np.ones(3)))
            t += 0.02
            time.sleep(0.02)

    tracker = threading.Thread(target=track, daemon=True)
    bus.threads.append(tracker)
    bus.closers.append(stop.set)
    tracker.start()
    args = _parser().parse_args(
        ["run", "--robot", str(robot_yaml), "--behavior", "face", "--robot-description",
         "--duration", "3", "--namespace", bus.names.namespace, "--connect", bus.endpoint,
         "--no-eye-frames", "--no-robot-warning", "10", "--json"])
    with caplog.at_level(logging.WARNING, logger="gazebot.io.drivers"):
        assert args.func(args) == 0
    stop.set()
    summary = json.loads(capsys.readouterr().out)
    assert summary["frames"] > 20 and summary["commands"] > 20

    # Where the face is, in the base frame, from the camera's pose written out above.
    face = CAMERA_XYZ + CAMERA_R @ FACE_IN_CAMERA
    np.testing.assert_allclose(CAMERA_R, pin.Quaternion(
        CAMERA_XYZW[3], *CAMERA_XYZW[:3]).toRotationMatrix(), atol=1e-12)
    target = targets[-1].point
    np.testing.assert_allclose([target.x, target.y, target.z], face, atol=1e-6)

    # The last head command, through the URDF's forward kinematics (Pinocchio, here).
    model = pin.buildModelFromXML(HEAD_URDF)
    data = model.createData()
    cmd = commands[-1]
    q = pin.neutral(model)
    for name, value in zip(cmd.joint_names, cmd.points[-1].positions, strict=True):
        q[model.joints[model.getJointId(name)].idx_q] = value
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    head = data.oMf[model.getFrameId("head")]
    gaze = head * pin.SE3(np.eye(3), np.array([0.09, 0.0, 0.05]))
    to_face = face - gaze.translation
    cos = float(gaze.rotation[:, 0] @ to_face / np.linalg.norm(to_face))
    assert math.degrees(math.acos(min(1.0, cos))) < 0.5
    assert abs(float(q[model.joints[model.getJointId("head_pan")].idx_q])) > 0.1  # it turned

    # The hand in a frame nobody publishes: dropped, counted, one warning.
    assert summary["untransformed"]["ghost_frame"] > 20
    warned = [r for r in caplog.records if "ghost_frame" in r.getMessage()]
    assert len(warned) == 1


def test_run_without_a_robot_description_stops_with_a_clear_message(bus, tmp_path, capsys):
    robot_yaml = tmp_path / "stackhead.yaml"
    robot_yaml.write_text(ROBOT_YAML)
    bus.listener()
    args = _parser().parse_args(
        ["run", "--robot", str(robot_yaml), "--robot-description", "/nobody/description",
         "--description-timeout", "0.5", "--namespace", bus.names.namespace,
         "--connect", bus.endpoint, "--no-eye-frames"])
    assert args.func(args) == 2
    err = capsys.readouterr().err
    assert "no robot description on /nobody/description within 0.5 s" in err


def test_a_yaml_without_a_model_file_names_the_option_that_supplies_one(tmp_path):
    from gazebot.core.config import ConfigError
    from gazebot.core.kinematics.robot import RobotModel

    robot_yaml = tmp_path / "stackhead.yaml"
    robot_yaml.write_text(ROBOT_YAML)
    with pytest.raises(ConfigError, match="--robot-description"):
        RobotModel.load(robot_yaml)


def test_a_published_description_that_is_not_a_urdf_is_a_config_error(tmp_path):
    from gazebot.core.config import ConfigError
    from gazebot.core.kinematics.robot import RobotModel
    from gazebot.core.kinematics.robot_config import load_robot_config

    robot_yaml = tmp_path / "stackhead.yaml"
    robot_yaml.write_text(ROBOT_YAML)
    config = load_robot_config(robot_yaml)[0]
    with pytest.raises(ConfigError, match="/robot_description: field '<urdf>'"):
        RobotModel.from_urdf_text(config, "<robot name='x'", "/robot_description")
    with pytest.raises(ConfigError, match="a joint named 'head_pan'"):
        RobotModel.from_urdf_text(config, "<robot name='x'><link name='a'/></robot>")
    model = RobotModel.from_urdf_text(config, HEAD_URDF)
    assert model.head_joints == ["head_pan", "head_tilt"] and model.model_kind == "urdf"





def test_tiagos_urdf_as_text_gives_the_model_its_file_gives():
    from gazebot.core.kinematics.model_files import package_search_path, resolve_package_uri
    from gazebot.core.kinematics.robot import RobotModel
    from gazebot.core.kinematics.robot_config import (
        configs_dir,
        load_robot_config,
        resolve_model_file,
    )

    if resolve_package_uri("package://example-robot-data/package.xml",
                           package_search_path()) is None:
        pytest.skip("example-robot-data is not installed (pip install 'example-robot-data>=6,<7')")

    path = configs_dir() / "robots" / "examples" / "tiago.yaml"
    config, _ = load_robot_config(path)
    urdf_file, kind = resolve_model_file(config, path)
    assert kind == "urdf"
    from_file = RobotModel.load(path)
    # The YAML without its urdf: line, the URDF as the stack would publish it (its meshes are
    # package:// URIs the kinematics never reads).
    bare = config.model_copy(update={"urdf": None})
    from_text = RobotModel.from_urdf_text(bare, urdf_file.read_text())
    assert from_text.head_joints == from_file.head_joints
    np.testing.assert_array_equal(from_text.lower, from_file.lower)
    np.testing.assert_array_equal(from_text.velocity_limits, from_file.velocity_limits)
    q = (from_file.lower + from_file.upper) / 3.0
    a, b = from_text.gaze_pose(q), from_file.gaze_pose(q)
    np.testing.assert_allclose(a.position, b.position, atol=1e-12)
    np.testing.assert_allclose(a.rotation, b.rotation, atol=1e-12)


def test_tracking_in_ever_new_frames_is_counted_in_bounded_space(bus):
    from gazebot.io.drivers.rmw.node import Received
    from gazebot.io.drivers.tf_buffer import TfBuffer, Transform
    from gazebot.io.drivers.zenoh_driver import MAX_FRAMES, OTHER_FRAMES, ZenohRobotDriver
    from gazebot.io.ros2 import convert as cv

    drv = ZenohRobotDriver(bus.listener(), bus.names, "engine", tf=TfBuffer())
    bus.closers.append(drv.close)
    drv._source = lambda part, rx: "mocap"  # identity is test_drivers_trust's; here: frames
    rx = Received("/t/tracking/giver_face", cv.POINT_STAMPED, None)
    for i in range(3 * MAX_FRAMES):
        drv._on_point("giver_face", cv.point_stamped(1.0 + 0.01 * i, [1.0, 0.0, 1.0], f"f{i}"),
                      rx)
    assert len(drv.untransformed) == MAX_FRAMES + 1
    assert drv.untransformed[OTHER_FRAMES] == 2 * MAX_FRAMES
    # a frame that has a transform is used, in the base frame
    drv.tf.add("world", "cam", 0.0, Transform(np.array([0.0, 0.0, 1.0]), np.eye(3)), static=True)
    drv._on_point("giver_face", cv.point_stamped(5.0, [1.0, 0.0, 0.5], "cam"), rx)
    sample = drv.wait_tracking(2.0)
    assert sample is not None and sample.t == pytest.approx(5.0)
    np.testing.assert_allclose(sample.giver_face, [1.0, 0.0, 1.5])


def test_tracked_tf_frames_under_another_parent_are_transformed_into_the_base(bus):
    from gazebot.core.types import TrackingFrame
    from gazebot.io.drivers.rmw.names import Names
    from gazebot.io.drivers.rmw.node import Received
    from gazebot.io.drivers.tf_buffer import TfBuffer, Transform
    from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
    from gazebot.io.ros2 import convert as cv

    names = Names(bus.names.namespace, tf_frames={"giver_face": "mocap/face"})
    drv = ZenohRobotDriver(bus.listener(), names, "engine", tf=TfBuffer())
    bus.closers.append(drv.close)
    drv._source = lambda part, rx: "mocap"  # identity is test_drivers_trust's; here: frames
    # the motion-capture frame: 2 m ahead of the base, turned half a turn about z
    half_turn = np.diag([-1.0, -1.0, 1.0])
    drv.tf.add("world", "mocap", 0.0, Transform(np.array([2.0, 0.0, 0.0]), half_turn),
               static=True)
    msg = cv.tracking_tf(TrackingFrame.make(3.0, giver_face=[0.5, 0.1, 1.6]), "mocap",
                         {"giver_face": "mocap/face"})
    drv._on_tf(drv._tf_codec.encode(msg), Received("/tf", cv.TF_MESSAGE, None))
    sample = drv.wait_tracking(2.0)
    assert sample is not None
    np.testing.assert_allclose(sample.giver_face, [1.5, -0.1, 1.6])
