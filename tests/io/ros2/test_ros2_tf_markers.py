"""The head's frames (``/tf``, ``/tf_static``) and the scene's markers, decoded by an
independent ROS 2 CDR decoder (mcap-ros2-support) from an MCAP gazebot wrote."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gazebot.core.kinematics.robot import RobotModel
from gazebot.io.ros2.markers import IDS, MARKER_ARRAY, RosMarker, Scene, marker_array
from gazebot.io.ros2.mcap_writer import McapRecorder
from gazebot.io.ros2.tf import HeadFrames, tf_message


@pytest.fixture(scope="module")
def robot() -> RobotModel:
    return RobotModel.load("sawyer")


def _decoded(path: Path) -> dict[str, list]:
    decoder = pytest.importorskip("mcap_ros2.decoder", reason="mcap-ros2-support not installed")
    from mcap.reader import make_reader

    out: dict[str, list] = {}
    with path.open("rb") as f:
        reader = make_reader(f, decoder_factories=[decoder.DecoderFactory()])
        for schema, ch, _, msg in reader.iter_decoded_messages():
            out.setdefault(ch.topic, []).append((schema.name, msg))
    return out


def _quat_matrix(q) -> np.ndarray:
    x, y, z, w = q.x, q.y, q.z, q.w
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def test_tf_chains_to_the_gaze_frame_the_engine_aims(robot, tmp_path):
    frames = HeadFrames(robot, "base")
    head = {n: 0.2 for n in robot.head_joints}
    path = tmp_path / "tf.mcap"
    with McapRecorder(path) as rec:
        rec.write("/tf", tf_message(1.0, frames.moving(head)), 1.0)
        rec.write("/tf_static", tf_message(1.0, frames.static()), 1.0)
    got = _decoded(path)
    (schema, tf), = got["/tf"]
    (_, static), = got["/tf_static"]
    assert schema == "tf2_msgs/msg/TFMessage"
    by_child = {t.child_frame_id: t for t in tf.transforms}
    assert {f"gazebot/{n}" for n in robot.head_joints} <= set(by_child)
    assert all(t.header.frame_id == "base" for t in tf.transforms)
    (gaze,) = static.transforms
    assert gaze.child_frame_id == "gaze"
    # Compose base -> joint (/tf) with joint -> gaze (/tf_static), as rviz2 does: the result is
    # the gaze pose the robot model gives for the same head position.
    parent = by_child[gaze.header.frame_id].transform
    R1, p1 = _quat_matrix(parent.rotation), np.array(
        [parent.translation.x, parent.translation.y, parent.translation.z])
    R2 = _quat_matrix(gaze.transform.rotation)
    p2 = np.array([gaze.transform.translation.x, gaze.transform.translation.y,
                   gaze.transform.translation.z])
    expect = robot.gaze_pose(robot.head_vector(head))
    np.testing.assert_allclose(p1 + R1 @ p2, expect.position, atol=1e-9)
    np.testing.assert_allclose((R1 @ R2)[:, 0], expect.line_of_sight, atol=1e-9)
    # and the head moves the frames
    other = frames.moving({n: -0.2 for n in robot.head_joints})
    assert not np.allclose(other[-1].rotation, frames.moving(head)[-1].rotation)


def test_markers_show_gaze_hands_face_and_phase_and_delete_what_is_unknown(tmp_path):
    scene = Scene(t=2.5, phase="reach", gaze_origin=[0.1, 0.0, 1.2], target=[0.6, 0.2, 1.0],
                  giver_hand=[0.6, 0.2, 1.0], giver_face=[1.0, 0.1, 1.6],
                  receiver_hand=[np.nan] * 3)
    path = tmp_path / "m.mcap"
    with McapRecorder(path) as rec:
        rec.write("/gazebot/markers", marker_array(scene, "base"), 2.5)
    (schema, arr), = _decoded(path)["/gazebot/markers"]
    assert schema == MARKER_ARRAY
    by_id = {m.id: m for m in arr.markers}
    assert set(by_id) == set(IDS.values())
    ray = by_id[IDS["gaze_ray"]]
    assert ray.type == RosMarker.ARROW and ray.action == RosMarker.ADD
    assert [(p.x, p.y, p.z) for p in ray.points] == [(0.1, 0.0, 1.2), (0.6, 0.2, 1.0)]
    face = by_id[IDS["giver_face"]]
    assert (face.pose.position.x, face.pose.position.z) == (1.0, 1.6)
    assert by_id[IDS["receiver_hand"]].action == RosMarker.DELETE  # not tracked
    assert by_id[IDS["phase"]].text == "reach"
    assert {m.header.frame_id for m in arr.markers} == {"base"}
    assert ray.header.stamp.sec == 2 and ray.header.stamp.nanosec == 500_000_000
