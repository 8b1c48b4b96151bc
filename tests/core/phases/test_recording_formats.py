"""The same recording as CSV, C3D and ROS 2 bag gives the same segments; CLI errors and the
empty table."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.cli import main
from gazebot.core.phases import PhaseConfig, segment
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.io.recordings import PointNames, load_recording


@pytest.fixture(scope="module")
def rec():
    return generate(21, SyntheticOptions(rate=100.0, noise=0.001, marker_offset=0.35)).trajectory


def _write_c3d(path, traj):
    import warnings

    import c3d

    warnings.filterwarnings("ignore", "No analog data found", UserWarning)  # points only
    w = c3d.Writer(point_rate=100.0, point_units="mm  ")
    w.set_point_labels(["RHAND_G", "RHAND_R", "HEAD_G"])
    frames = []
    for i in range(len(traj)):
        pts = np.zeros((3, 5), dtype=np.float32)
        for k, p in enumerate((traj.giver_hand[i], traj.receiver_hand[i], traj.giver_face[i])):
            pts[k, :3] = p * 1000.0
        frames.append((pts, np.zeros((0, 0), dtype=np.float32)))
    w.add_frames(frames)
    with open(path, "wb") as fh:
        w.write(fh)


def _write_bag(path, traj):
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    Pose = ts.types["geometry_msgs/msg/PoseStamped"]
    PointS = ts.types["geometry_msgs/msg/PointStamped"]
    Hdr = ts.types["std_msgs/msg/Header"]
    Time = ts.types["builtin_interfaces/msg/Time"]
    P = ts.types["geometry_msgs/msg/Point"]
    Q = ts.types["geometry_msgs/msg/Quaternion"]
    PoseM = ts.types["geometry_msgs/msg/Pose"]
    with Writer(path, version=9) as w:
        cg = w.add_connection("/giver/hand", Pose.__msgtype__, typestore=ts)
        cr = w.add_connection("/robot/gripper", PointS.__msgtype__, typestore=ts)
        for i, t in enumerate(traj.t):
            sec = int(t)
            hdr = Hdr(stamp=Time(sec=sec, nanosec=int(round((t - sec) * 1e9))), frame_id="base")
            g, r = traj.giver_hand[i], traj.receiver_hand[i]
            stamp = int(t * 1e9) + 1
            if np.isfinite(g).all():
                msg = Pose(
                    header=hdr,
                    pose=PoseM(
                        position=P(x=g[0], y=g[1], z=g[2]),
                        orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0),
                    ),
                )
                w.write(cg, stamp, ts.serialize_cdr(msg, Pose.__msgtype__))
            if np.isfinite(r).all():
                msg = PointS(header=hdr, point=P(x=r[0], y=r[1], z=r[2]))
                w.write(cr, stamp, ts.serialize_cdr(msg, PointS.__msgtype__))


def test_csv_c3d_and_ros2_bag_of_one_recording_give_the_same_segments(rec, tmp_path):
    rec.to_csv(tmp_path / "r.csv")
    _write_c3d(tmp_path / "r.c3d", rec)
    _write_bag(tmp_path / "bag", rec)
    a = load_recording(tmp_path / "r.csv")
    b = load_recording(tmp_path / "r.c3d", PointNames("RHAND_G", "RHAND_R", "HEAD_G"))
    c = load_recording(tmp_path / "bag", PointNames("/giver/hand", "/robot/gripper"))
    assert b.unit.strip() == "mm" and abs(b.rate - 100.0) < 1e-6
    ref = segment(a.trajectory, PhaseConfig())
    assert len(ref) == 3
    for other in (b, c):
        segs = segment(other.trajectory, PhaseConfig())
        assert [s.phase for s in segs] == [s.phase for s in ref]
        for s, r in zip(segs, ref, strict=True):
            # float32 C3D storage and nanosecond bag stamps: well under one sample.
            assert abs(s.start - r.start) < 0.005 and abs(s.end - r.end) < 0.005


def test_csv_reads_nan_and_empty_cells_as_missing(tmp_path):
    f = tmp_path / "n.csv"
    f.write_text(
        "t,giver_hand_x,giver_hand_y,giver_hand_z,receiver_hand_x,receiver_hand_y,"
        "receiver_hand_z\n0,NaN,0,0,1,1,1\n0.1,nan,,0,1,1,1\n0.2,0,0,0,1,1,1\n"
    )
    t = load_recording(f).trajectory
    assert np.isnan(t.giver_hand[:2]).all() and np.isfinite(t.giver_hand[2]).all()


def test_no_handover_prints_an_empty_table_and_exits_0(tmp_path, capsys):
    t = np.arange(0, 3, 0.01)
    f = tmp_path / "still.csv"
    rows = [
        "t,giver_hand_x,giver_hand_y,giver_hand_z,receiver_hand_x,receiver_hand_y,receiver_hand_z"
    ]
    rows += [f"{x:.2f},1,0,1,0.3,0,1" for x in t]
    f.write_text("\n".join(rows) + "\n")
    assert main(["phases", str(f)]) == 0
    out = capsys.readouterr().out
    assert "no handover found" in out and "100.0 Hz" in out and "m, s" in out


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--giver-hand", "nope"], "no point named 'nope'"),
        (["--unit", "furlong"], "unit 'furlong'"),
        ([], None),
    ],
)
def test_bad_input_fails_with_the_file_name_and_exit_2(args, needle, rec, tmp_path, capsys):
    f = tmp_path / "r.csv"
    rec.to_csv(f)
    target = f if needle else tmp_path / "missing.c3d"
    assert main(["phases", str(target), *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"gazebot: error: {target}: ")
    if needle:
        assert needle in err and "giver_hand" in err or "unit" in err


def test_unreadable_c3d_fails_with_exit_2(tmp_path, capsys):
    f = tmp_path / "junk.c3d"
    f.write_bytes(b"not a c3d file at all")
    assert main(["phases", str(f)]) == 2
    assert capsys.readouterr().err.startswith(f"gazebot: error: {f}: ")
