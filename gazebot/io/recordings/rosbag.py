"""ROS 1 and ROS 2 bags (``rosbags``, no ROS install). Names are topics carrying
``geometry_msgs/PoseStamped``, ``PointStamped`` or ``TransformStamped``, and the child frames
of ``/tf`` (``tf2_msgs/TFMessage``). Times are the message header stamps (s). Points are
sampled on the union of all stamps (each name's position linearly interpolated between its
own messages, missing outside them and across gaps longer than ``max_gap``).
"""

from __future__ import annotations

from pathlib import Path
from typing import cast

from gazebot.io.recordings import ros_shapes as shape
from gazebot.io.recordings.base import (
    PointNames,
    Recording,
    RecordingError,
    RecordingLimits,
    bound_streams,
    build,
    sample_streams,
)

_POSE = ("geometry_msgs/msg/PoseStamped", "geometry_msgs/PoseStamped")
_POINT = ("geometry_msgs/msg/PointStamped", "geometry_msgs/PointStamped")
_TF = ("geometry_msgs/msg/TransformStamped", "geometry_msgs/TransformStamped")
_TFMSG = ("tf2_msgs/msg/TFMessage", "tf2_msgs/TFMessage")


def read_bag(
    path: str | Path,
    names: PointNames | None = None,
    max_gap: float = 0.25,
    limits: RecordingLimits | None = None,
) -> Recording:
    """Read the point streams of a ROS 1 (``.bag``) or ROS 2 (folder or ``.mcap``/``.db3``) bag;
    ``max_gap``: longest interpolation gap of one stream (s); ``limits``: see
    :class:`~gazebot.io.recordings.base.RecordingLimits`.

    Raises:
        RecordingError: Not a readable bag, no usable topic, or a name the bag lacks.
    """
    from rosbags.highlevel import AnyReader

    path = Path(path)
    bag = path.parent if path.is_file() and path.suffix in (".db3", ".mcap") else path
    series: dict[str, list[tuple[float, float, float, float]]] = {}
    try:
        with AnyReader([bag]) as reader:
            conns = [c for c in reader.connections if c.msgtype in _POSE + _POINT + _TF + _TFMSG]
            for conn, _, raw in reader.messages(connections=conns):
                msg = reader.deserialize(raw, conn.msgtype)
                if conn.msgtype in _TFMSG:
                    for tf in cast(shape.TFMessage, msg).transforms:
                        tr = tf.transform.translation
                        series.setdefault(tf.child_frame_id.lstrip("/"), []).append(
                            (shape.stamp(tf.header), tr.x, tr.y, tr.z)
                        )
                    continue
                p: shape.XYZ
                if conn.msgtype in _POSE:
                    pose = cast(shape.PoseStamped, msg)
                    header, p = pose.header, pose.pose.position
                elif conn.msgtype in _POINT:
                    point = cast(shape.PointStamped, msg)
                    header, p = point.header, point.point
                else:
                    tfs = cast(shape.TransformStamped, msg)
                    header, p = tfs.header, tfs.transform.translation
                series.setdefault(conn.topic, []).append((shape.stamp(header), p.x, p.y, p.z))
    except RecordingError:
        raise
    except Exception as exc:  # rosbags raises its own error types for unreadable bags
        raise RecordingError(path, f"not a readable ROS bag ({exc})") from None
    if not series:
        raise RecordingError(path, "no PoseStamped, PointStamped, TransformStamped or /tf data")
    limits = limits or RecordingLimits()
    series, beyond, namer = bound_streams(path, series, limits)
    t, points = sample_streams(series, max_gap)
    rec = build(
        path,
        "rosbag",
        t,
        points,
        names or PointNames(),
        "m",
        (None, None, None),
        limits=limits,
        where=namer(t),
    )
    rec.out_of_workspace += sum(beyond[n] for n in {n for n in rec.names if n is not None})
    return rec
