"""ROS 1 and ROS 2 bags (``rosbags``, no ROS install). Names are topics carrying
``geometry_msgs/PoseStamped``, ``PointStamped`` or ``TransformStamped``, and the child frames
of ``/tf`` (``tf2_msgs/TFMessage``). Times are the message header stamps (s). Points are
sampled on the union of all stamps (each name's position linearly interpolated between its
own messages, missing outside them and across gaps longer than ``max_gap``).
"""

from __future__ import annotations

import os
import struct
from pathlib import Path
from typing import BinaryIO, cast

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
from gazebot.io.recordings.mcap_records import ChunkLimitError, check_chunk, check_mcap_chunks

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
    limits = limits or RecordingLimits()
    try:
        # rosbags decompresses whatever a chunk declares: the limits are checked first.
        _check_chunks(path if path.is_file() else bag, limits)
    except ChunkLimitError as exc:
        raise RecordingError(path, f"refused: {exc}") from None
    except OSError:
        pass  # rosbags reports an unreadable bag below
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


_BAG1_MAGIC = b"#ROSBAG V2.0\n"
_BAG1_CHUNK = b"\x05"  # the op of a chunk record


def _check_chunks(bag: Path, limits: RecordingLimits) -> None:
    """Check the chunks of a ROS 2 bag's MCAP files, or of a ROS 1 bag, against ``limits``
    (declared uncompressed size, compression ratio) before rosbags decompresses them.

    Raises:
        ChunkLimitError: A chunk over a limit (naming its file).
    """
    files = sorted(bag.glob("*.mcap")) if bag.is_dir() else [bag]
    for file in files:
        with open(file, "rb") as f:
            try:
                if file.suffix == ".mcap":
                    check_mcap_chunks(f, limits.max_chunk_bytes, limits.max_chunk_ratio)
                elif f.read(len(_BAG1_MAGIC)) == _BAG1_MAGIC:
                    _check_bag1_chunks(f, limits)
            except ChunkLimitError as exc:
                where = f"{file.name}: " if file != bag else ""
                raise ChunkLimitError(f"{where}{exc}") from None


def _check_bag1_chunks(f: BinaryIO, limits: RecordingLimits) -> None:
    """The chunk records of a ROS 1 bag (format 2.0, after its magic): each record is a header
    (length-prefixed ``name=value`` fields) and data, both with a 32-bit length; a chunk
    declares its uncompressed ``size``. Stops quietly where the file stops parsing."""
    size = os.fstat(f.fileno()).st_size
    number = 0
    while True:
        head = f.read(4)
        if len(head) < 4:
            return
        (header_len,) = struct.unpack("<I", head)
        if header_len > size - f.tell():
            return
        fields = _bag1_fields(f.read(header_len))
        tail = f.read(4)
        if len(tail) < 4:
            return
        (data_len,) = struct.unpack("<I", tail)
        if fields.get(b"op") == _BAG1_CHUNK:
            number += 1
            declared = fields.get(b"size", b"")
            if fields.get(b"compression", b"none") != b"none" and len(declared) == 4:
                check_chunk(f"chunk {number}", struct.unpack("<I", declared)[0], data_len,
                            limits.max_chunk_bytes, limits.max_chunk_ratio)
        f.seek(data_len, os.SEEK_CUR)


def _bag1_fields(header: bytes) -> dict[bytes, bytes]:
    """The ``name=value`` fields of a ROS 1 bag record header."""
    out: dict[bytes, bytes] = {}
    pos = 0
    while pos + 4 <= len(header):
        (n,) = struct.unpack_from("<I", header, pos)
        field = header[pos + 4 : pos + 4 + n]
        pos += 4 + n
        name, eq, value = field.partition(b"=")
        if eq:
            out[name] = value
    return out
