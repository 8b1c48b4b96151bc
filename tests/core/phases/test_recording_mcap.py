"""MCAP recordings: gazebot's own (default topic names, gripper and load share) and any
rosbag2 MCAP with PointStamped, PoseStamped or /tf give the same segments as the CSV; broken
files and messages are clear errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gazebot.apps.cli import main
from gazebot.core.phases import PhaseConfig, segment
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.io.recordings import PointNames, RecordingError, load_recording
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2 import topics as tp
from gazebot.io.ros2.mcap_writer import McapRecorder


@pytest.fixture(scope="module")
def traj():
    return generate(21, SyntheticOptions(rate=100.0, noise=0.001, marker_offset=0.35)).trajectory


def _write_gazebot_mcap(path: Path, traj, grip_from: float | None = None) -> None:
    with McapRecorder(path) as rec:
        for i, t in enumerate(traj.t):
            for body in cv.BODIES:
                p = getattr(traj, body)[i]
                if np.isfinite(p).all():
                    rec.write(tp.TRACKING[body].resolve(), cv.point_stamped(t, p, "world"), t)
            if grip_from is not None:
                rec.write(tp.GRIPPER.resolve(), cv.gripper_state(t, t >= grip_from), t)
                rec.write(tp.LOAD_SHARE.resolve(), cv.load_share(t, 0.5 * (t >= grip_from)), t)


def _write_rosbag2_mcap(path: Path, traj) -> Path:
    """A ROS 2 bag in MCAP storage written by rosbags' own writer: the giver's hand as
    PoseStamped, the receiver's hand as a /tf frame."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        cg = w.add_connection("/mocap/giver_hand/pose", "geometry_msgs/msg/PoseStamped",
                              typestore=ts)
        ctf = w.add_connection("/tf", "tf2_msgs/msg/TFMessage", typestore=ts)
        for i, t in enumerate(traj.t):
            sec = int(t)
            hdr = T["std_msgs/msg/Header"](
                stamp=T["builtin_interfaces/msg/Time"](sec=sec, nanosec=round((t - sec) * 1e9)),
                frame_id="world",
            )
            g, r = traj.giver_hand[i], traj.receiver_hand[i]
            q = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
            stamp = round(t * 1e9)
            if np.isfinite(g).all():
                pose = T["geometry_msgs/msg/Pose"](
                    position=T["geometry_msgs/msg/Point"](x=g[0], y=g[1], z=g[2]), orientation=q)
                msg = T["geometry_msgs/msg/PoseStamped"](header=hdr, pose=pose)
                w.write(cg, stamp, ts.serialize_cdr(msg, msg.__msgtype__))
            if np.isfinite(r).all():
                tf = T["geometry_msgs/msg/TransformStamped"](
                    header=hdr, child_frame_id="receiver_hand",
                    transform=T["geometry_msgs/msg/Transform"](
                        translation=T["geometry_msgs/msg/Vector3"](x=r[0], y=r[1], z=r[2]),
                        rotation=q))
                msg = T["tf2_msgs/msg/TFMessage"](transforms=[tf])
                w.write(ctf, stamp, ts.serialize_cdr(msg, msg.__msgtype__))
    (mcap,) = path.glob("*.mcap")
    return mcap


def _same_segments(a, ref) -> None:
    assert [s.phase for s in a] == [s.phase for s in ref]
    for s, r in zip(a, ref, strict=True):
        assert abs(s.start - r.start) < 0.005 and abs(s.end - r.end) < 0.005


def test_gazebot_mcap_reads_with_default_names_and_gives_the_csvs_segments(traj, tmp_path):
    traj.to_csv(tmp_path / "r.csv")
    ref = segment(load_recording(tmp_path / "r.csv").trajectory, PhaseConfig())
    assert len(ref) == 3
    _write_gazebot_mcap(tmp_path / "r.mcap", traj)
    rec = load_recording(tmp_path / "r.mcap")
    assert rec.format == "mcap"
    assert rec.names == ("/gazebot/tracking/giver_hand", "/gazebot/tracking/receiver_hand",
                         "/gazebot/tracking/giver_face")
    _same_segments(segment(rec.trajectory, PhaseConfig()), ref)


def test_gripper_and_load_share_become_the_trajectorys_evidence(traj, tmp_path):
    _write_gazebot_mcap(tmp_path / "g.mcap", traj, grip_from=float(traj.t[50]))
    t = load_recording(tmp_path / "g.mcap").trajectory
    assert t.t.shape == traj.t.shape
    closed = np.arange(t.t.size) >= 50  # from the 50th sample's stamp on
    np.testing.assert_array_equal(t.gripper_closed, closed.astype(float))
    np.testing.assert_array_equal(t.load_share, np.where(closed, 0.5, 0.0))


def test_rosbag2_mcap_with_pose_stamped_and_tf_gives_the_csvs_segments(traj, tmp_path):
    traj.to_csv(tmp_path / "r.csv")
    ref = segment(load_recording(tmp_path / "r.csv").trajectory, PhaseConfig())
    mcap = _write_rosbag2_mcap(tmp_path / "bag", traj)
    with pytest.raises(RecordingError, match="which point is giver_hand"):
        load_recording(mcap)
    rec = load_recording(mcap, PointNames("/mocap/giver_hand/pose", "receiver_hand"))
    assert rec.available == ("/mocap/giver_hand/pose", "receiver_hand")
    _same_segments(segment(rec.trajectory, PhaseConfig()), ref)


def test_non_finite_coordinates_are_missing_samples(tmp_path):
    path = tmp_path / "nan.mcap"
    with McapRecorder(path) as rec:
        for i in range(4):
            msg = cv.point_stamped(i * 0.1, [1.0, 0.0, 1.0], "world")
            if i == 1:
                msg.point.x = float("nan")  # what a tracker with a lost marker may send
            for body in ("giver_hand", "receiver_hand"):
                rec.write(tp.TRACKING[body].resolve(), msg, i * 0.1)
    t = load_recording(path).trajectory
    assert t.t.tolist() == pytest.approx([0.0, 0.2, 0.3])  # the NaN sample is not a sample


def test_a_message_that_does_not_decode_names_its_topic(tmp_path):
    from mcap.writer import Writer

    from gazebot.io.ros2 import typestore

    path = tmp_path / "bad.mcap"
    with path.open("wb") as f:
        w = Writer(f)
        w.start(profile="ros2")
        definition, _ = typestore().generate_msgdef(cv.POINT_STAMPED, ros_version=2)
        sid = w.register_schema(cv.POINT_STAMPED, "ros2msg", definition.encode())
        cid = w.register_channel("/gazebot/tracking/giver_hand", "cdr", sid)
        w.add_message(cid, log_time=10**9, data=b"\x00\x01\x00\x00\x01\x02", publish_time=10**9)
        w.finish()
    with pytest.raises(RecordingError, match=r"topic /gazebot/tracking/giver_hand: message at "
                                             r"log time 1.000 s is not a"):
        load_recording(path)


def test_a_file_that_is_not_mcap_is_a_clear_error(tmp_path):
    path = tmp_path / "x.mcap"
    path.write_bytes(b"this is not an MCAP file at all")
    with pytest.raises(RecordingError, match="not a readable MCAP file"):
        load_recording(path)


def test_gazebot_phases_prints_the_phases_of_an_mcap(traj, tmp_path, capsys):
    _write_gazebot_mcap(tmp_path / "r.mcap", traj)
    assert main(["phases", str(tmp_path / "r.mcap")]) == 0
    out = capsys.readouterr().out
    assert "mcap, " in out
    assert [line.split()[1] for line in out.splitlines()[2:]] == ["reach", "transfer", "retreat"]


def test_a_recording_cut_short_reads_up_to_the_cut_with_a_warning(traj, tmp_path, capsys):
    """A recorder killed mid-file leaves no footer: every complete chunk is still read."""
    path = tmp_path / "cut.mcap"
    with McapRecorder(path, chunk_size=4096) as rec:
        for i, t in enumerate(traj.t):
            for body in ("giver_hand", "receiver_hand"):
                p = getattr(traj, body)[i]
                if np.isfinite(p).all():
                    rec.write(tp.TRACKING[body].resolve(), cv.point_stamped(t, p, "world"), t)
    data = path.read_bytes()
    cut = tmp_path / "cut_short.mcap"
    cut.write_bytes(data[: len(data) * 2 // 3])
    whole, short = load_recording(path), load_recording(cut)
    assert whole.notes == ()
    (note,) = short.notes
    assert "cut short" in note
    n = len(short.trajectory)
    assert 0.5 * len(whole.trajectory) < n < len(whole.trajectory)
    np.testing.assert_array_equal(short.trajectory.giver_hand, whole.trajectory.giver_hand[:n])
    assert main(["phases", str(cut)]) == 0
    assert "warning" in capsys.readouterr().err
    cut.write_bytes(data[:200])
    with pytest.raises(RecordingError, match="before the first complete chunk"):
        load_recording(cut)
