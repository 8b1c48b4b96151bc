"""ROS 1 and ROS 2 bags (``rosbags``, no ROS install). Names are topics carrying
``geometry_msgs/PoseStamped``, ``PointStamped`` or ``TransformStamped``, and the child frames
of ``/tf`` (``tf2_msgs/TFMessage``). Times are the message header stamps (s). Points are
sampled on the union of all stamps (each name's position linearly interpolated between its
own messages, missing outside them and across gaps longer than ``max_gap``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gazebot.recordings.base import (
    PointNames,
    Recording,
    RecordingError,
    RecordingLimits,
    build,
    in_workspace,
)

_POSE = ("geometry_msgs/msg/PoseStamped", "geometry_msgs/PoseStamped")
_POINT = ("geometry_msgs/msg/PointStamped", "geometry_msgs/PointStamped")
_TF = ("geometry_msgs/msg/TransformStamped", "geometry_msgs/TransformStamped")
_TFMSG = ("tf2_msgs/msg/TFMessage", "tf2_msgs/TFMessage")


def _stamp(header: object) -> float:
    st = header.stamp  # type: ignore[attr-defined]
    return float(st.sec) + 1e-9 * float(st.nanosec)


def read_bag(
    path: str | Path,
    names: PointNames | None = None,
    max_gap: float = 0.25,
    limits: RecordingLimits | None = None,
) -> Recording:
    """Read the point streams of a ROS 1 (``.bag``) or ROS 2 (folder or ``.mcap``/``.db3``) bag;
    ``max_gap``: longest interpolation gap of one stream (s); ``limits``: see
    :class:`~gazebot.recordings.base.RecordingLimits`.

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
                    for tf in msg.transforms:
                        tr = tf.transform.translation
                        series.setdefault(tf.child_frame_id.lstrip("/"), []).append(
                            (_stamp(tf.header), tr.x, tr.y, tr.z)
                        )
                    continue
                if conn.msgtype in _POSE:
                    p = msg.pose.position
                elif conn.msgtype in _POINT:
                    p = msg.point
                else:
                    p = msg.transform.translation
                series.setdefault(conn.topic, []).append((_stamp(msg.header), p.x, p.y, p.z))
    except RecordingError:
        raise
    except Exception as exc:  # rosbags raises its own error types for unreadable bags
        raise RecordingError(path, f"not a readable ROS bag ({exc})") from None
    if not series:
        raise RecordingError(path, "no PoseStamped, PointStamped, TransformStamped or /tf data")
    stamps = np.concatenate([[s[0] for s in v] for v in series.values()])
    finite = stamps[np.isfinite(stamps)]
    t = np.unique(finite)
    if finite.shape[0] < stamps.shape[0]:
        raise RecordingError(path, "a message header stamp is not a finite time")

    def where(i: int) -> str:
        topics = sorted(n for n, rows in series.items() if any(r[0] == t[i] for r in rows))
        return f"the message stamped {t[i]:.9g} s on {', '.join(topics)}"

    limits = limits or RecordingLimits()
    points: dict[str, np.ndarray] = {}
    beyond: dict[str, int] = {}
    for name, rows in series.items():
        a = np.array(sorted(rows))
        _, keep = np.unique(a[:, 0], return_index=True)
        a = a[keep]
        # A message beyond the workspace (or not finite) is missing: left out before
        # interpolating, where 1e308 would overflow and smear into its neighbours.
        xyz, n_out = in_workspace(a[:, 1:], limits.workspace_m)
        beyond[name] = n_out
        a = a[np.isfinite(xyz).all(axis=1)]
        if a.shape[0] == 0:
            points[name] = np.full((t.shape[0], 3), np.nan)
            continue
        p = np.stack([np.interp(t, a[:, 0], a[:, k]) for k in (1, 2, 3)], axis=1)
        j = np.searchsorted(a[:, 0], t, side="right")
        exact = np.isin(t, a[:, 0])
        inside = (j > 0) & (j < a.shape[0])
        gap = np.full(t.shape[0], np.inf)
        gap[inside] = a[j[inside], 0] - a[j[inside] - 1, 0]
        p[~exact & (gap > max_gap)] = np.nan
        points[name] = p
    rec = build(
        path,
        "rosbag",
        t,
        points,
        names or PointNames(),
        "m",
        (None, None, None),
        limits=limits,
        where=where,
    )
    rec.out_of_workspace += sum(beyond[n] for n in set(rec.names) - {None})
    return rec
