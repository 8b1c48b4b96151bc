"""Small recordings in each format the readers take (CSV, C3D, pose folder, ROS 2 bag), written
from plain arrays so a test can put any value (an outlier stamp, 1e308) where it wants."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

POINTS = ("giver_hand", "receiver_hand", "giver_face")


def sample(n: int = 60, rate: float = 50.0) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """``n`` samples at ``rate``: a giver's hand moving toward a still receiver hand."""
    t = np.arange(n) / rate
    s = np.linspace(0.0, 1.0, n)[:, None]
    hand = np.array([1.0, 0.0, 1.0]) + s * np.array([-0.4, 0.0, 0.0])
    return t, {
        "giver_hand": hand,
        "receiver_hand": np.tile([0.4, -0.2, 1.0], (n, 1)),
        "giver_face": np.tile([1.1, 0.0, 1.6], (n, 1)),
    }


def write_csv(path: Path, t: np.ndarray, points: dict[str, np.ndarray]) -> Path:
    cols = ["t"] + [f"{p}_{a}" for p in points for a in "xyz"]
    rows = [",".join(cols)]
    for i in range(t.shape[0]):
        cells = [repr(float(t[i]))] + [repr(float(v)) for p in points.values() for v in p[i]]
        rows.append(",".join(cells))
    path.write_text("\n".join(rows) + "\n")
    return path


def write_c3d(path: Path, points: dict[str, np.ndarray], rate: float = 50.0) -> Path:
    """Float C3D in metres (``POINT:UNITS`` m)."""
    import c3d

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "No analog data found", UserWarning)
        w = c3d.Writer(point_rate=rate, point_units="m   ")
        w.set_point_labels(list(points))
        n = next(iter(points.values())).shape[0]
        frames = []
        for i in range(n):
            pts = np.zeros((len(points), 5), dtype=np.float32)
            for k, p in enumerate(points.values()):
                with np.errstate(over="ignore"):
                    pts[k, :3] = p[i]
            frames.append((pts, np.zeros((0, 0), dtype=np.float32)))
        w.add_frames(frames)
        with open(path, "wb") as fh:
            w.write(fh)
    return path


def write_pose_folder(path: Path, points: dict[str, np.ndarray]) -> Path:
    path.mkdir(parents=True, exist_ok=True)
    for name, p in points.items():
        lines = ["x,y,z,q0,q1,q2,q3"] + [",".join(map(repr, map(float, r))) + ",1,0,0,0" for r in p]
        (path / f"{name}_pose_saved.csv").write_text("\n".join(lines) + "\n")
    return path


def write_bag(path: Path, t: np.ndarray, points: dict[str, np.ndarray], sec=None) -> Path:
    """A ROS 2 bag with one ``PointStamped`` topic ``/NAME`` per point; ``sec``: header seconds
    per sample (default: from ``t``)."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    PointS = ts.types["geometry_msgs/msg/PointStamped"]
    Hdr = ts.types["std_msgs/msg/Header"]
    Time = ts.types["builtin_interfaces/msg/Time"]
    P = ts.types["geometry_msgs/msg/Point"]
    with Writer(path, version=9) as w:
        conns = {n: w.add_connection(f"/{n}", PointS.__msgtype__, typestore=ts) for n in points}
        for i, ti in enumerate(t):
            s = int(ti) if sec is None else int(sec[i])
            ns = int(round((ti - int(ti)) * 1e9)) % 1_000_000_000
            hdr = Hdr(stamp=Time(sec=s, nanosec=ns), frame_id="base")
            for n, p in points.items():
                msg = PointS(header=hdr, point=P(x=p[i][0], y=p[i][1], z=p[i][2]))
                w.write(conns[n], i + 1, ts.serialize_cdr(msg, PointS.__msgtype__))
    return path
