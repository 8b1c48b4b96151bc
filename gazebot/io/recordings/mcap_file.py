"""MCAP files with ROS 2 messages (``ros2`` profile, CDR, ``ros2msg`` schemas), as
``ros2 bag record -s mcap``, Foxglove and ``gazebot demo`` write them; read with the ``mcap``
library and decoded by rosbags from the definitions embedded in the file.

Names are topics carrying ``geometry_msgs/PointStamped``, ``PoseStamped`` or
``TransformStamped``, and the child frames of ``/tf`` (``tf2_msgs/TFMessage``). Topics ending
in ``tracking/giver_hand``, ``tracking/receiver_hand`` and ``tracking/giver_face`` (gazebot's
own) are the default names; ``gazebot_msgs/GripperState`` and ``LoadShare`` become the
trajectory's gripper and load-share evidence. Times are header stamps (s); points are sampled
as in :mod:`.rosbag`. A coordinate that is NaN or infinite is a missing sample.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from pathlib import Path
from typing import Any, BinaryIO, cast

from gazebot.io.recordings import ros_shapes as shape
from gazebot.io.recordings.base import (
    PointNames,
    Recording,
    RecordingError,
    RecordingLimits,
    bound_streams,
    build,
    hold_values,
    sample_streams,
)
from gazebot.io.recordings.mcap_records import (
    CappedReads,
    ChunkLimitError,
    DamagedError,
    McapRecords,
    iter_messages,
)
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2 import topics as ros_topics

_POINT = cv.POINT_STAMPED
_POSE = cv.POSE_STAMPED
_TRANSFORM = cv.TRANSFORM_STAMPED
_TF = cv.TF_MESSAGE
_GRIPPER = cv.GRIPPER_STATE
_LOAD = cv.LOAD_SHARE
_WANTED = (_POINT, _POSE, _TRANSFORM, _TF, _GRIPPER, _LOAD)
# gazebot's own tracking topics (the bus's names), in the trajectory's order of bodies.
_DEFAULT_SUFFIX = tuple(ros_topics.TRACKING[body].name for body in cv.BODIES)


def _ros2_name(name: str) -> str:
    pkg, _, short = name.rpartition("/")
    return name if "/msg/" in name else f"{pkg.split('/')[0]}/msg/{short}"


def _default(topics: list[str], suffix: str) -> str | None:
    hits = [t for t in topics if t.rstrip("/").endswith(suffix)]
    return hits[0] if len(hits) == 1 else None


def read_mcap(
    path: str | Path,
    names: PointNames | None = None,
    max_gap: float = 0.25,
    limits: RecordingLimits | None = None,
) -> Recording:
    """Read the point streams (and gripper / load share) of an MCAP file of ROS 2 messages;
    ``limits``: see :class:`~gazebot.io.recordings.base.RecordingLimits` (stamps, workspace).

    Raises:
        RecordingError: Not a readable MCAP file, a message that does not decode as its schema
            (naming topic and log time), no usable topic, or a name the file lacks.
    """
    from rosbags.typesys import Stores, get_typestore

    from gazebot.io.ros2.typestore import definition_types

    path = Path(path)
    store = get_typestore(Stores.EMPTY)  # the file's own definitions, nothing else
    known: set[int] = set()
    series: dict[str, list[tuple[float, float, float, float]]] = {}
    grip: list[tuple[float, float]] = []
    load: list[tuple[float, float]] = []

    def add(name: str, header: shape.Header, p: shape.XYZ) -> None:
        # Every row is kept here: bound_streams checks stamps and bounds coordinates (counted).
        series.setdefault(name, []).append((shape.stamp(header), float(p.x), float(p.y),
                                            float(p.z)))

    notes: list[str] = []
    limits = limits or RecordingLimits()
    try:
        with open(path, "rb") as raw:
            f = CappedReads(raw)
            for schema, channel, message in _messages(f, notes, limits):  # type: ignore[arg-type]
                if schema is None or schema.encoding != "ros2msg":
                    continue
                if channel.message_encoding != "cdr":
                    continue
                typ = _ros2_name(schema.name)
                if typ not in _WANTED:
                    continue
                if schema.id not in known:
                    types = definition_types(typ, schema.data.decode())
                    store.register({k: v for k, v in types.items() if k not in store.types})
                    known.add(schema.id)
                try:
                    msg = store.deserialize_cdr(message.data, typ)
                except Exception as exc:  # rosbags' SerdeError and friends
                    raise RecordingError(
                        path, f"topic {channel.topic}: message at log time "
                        f"{message.log_time * 1e-9:.3f} s is not a {typ} ({exc})",
                    ) from None
                if typ == _TF:
                    for tf in cast(shape.TFMessage, msg).transforms:
                        add(tf.child_frame_id.lstrip("/"), tf.header, tf.transform.translation)
                elif typ == _POINT:
                    point = cast(shape.PointStamped, msg)
                    add(channel.topic, point.header, point.point)
                elif typ == _POSE:
                    pose = cast(shape.PoseStamped, msg)
                    add(channel.topic, pose.header, pose.pose.position)
                elif typ == _TRANSFORM:
                    tfs = cast(shape.TransformStamped, msg)
                    add(channel.topic, tfs.header, tfs.transform.translation)
                elif typ == _GRIPPER:
                    gripper = cast(shape.GripperState, msg)
                    grip.append((shape.stamp(gripper.header), 1.0 if gripper.closed else 0.0))
                else:
                    share = cast(shape.LoadShare, msg)
                    if 0.0 <= share.share <= 1.0:  # NaN or out of range: unknown
                        load.append((shape.stamp(share.header), float(share.share)))
    except (RecordingError, FileNotFoundError):
        raise
    except ChunkLimitError as exc:
        raise RecordingError(path, f"refused: {exc}") from None
    except Exception as exc:  # mcap, its decompressors (zstd, lz4), struct: a damaged file
        # McapError, MessageError, OSError, ValueError, KeyError, struct.error, ZstdError...
        raise RecordingError(path, f"not a readable MCAP file of ROS 2 messages ({exc})") from None
    if not series:
        raise RecordingError(path, "no PoseStamped, PointStamped, TransformStamped or /tf data")
    series, beyond, namer = bound_streams(path, series, limits)
    t, points = sample_streams(series, max_gap)
    topics = sorted(points)
    hand, receiver, face = (_default(topics, s) for s in _DEFAULT_SUFFIX)
    defaults = (hand, receiver, face)
    extra = {"gripper_closed": hold_values(t, grip), "load_share": hold_values(t, load)}
    rec = build(
        path, "mcap", t, points, names or PointNames(), "m", defaults,
        extra, tuple(notes), limits=limits, where=namer(t),
    )
    rec.out_of_workspace += sum(beyond[n] for n in {n for n in rec.names if n is not None})
    return rec


def _has_footer(f: BinaryIO) -> bool:
    """Whether ``f`` is a finished MCAP file (its footer and summary read)."""
    from mcap.exceptions import McapError
    from mcap.reader import make_reader

    try:
        make_reader(f).get_summary()
    except (McapError, struct.error, ValueError):  # struct.error: shorter than a record
        return False
    finally:
        f.seek(0)
    return True


def _messages(
    f: BinaryIO, notes: list[str], limits: RecordingLimits
) -> Iterator[tuple[Any, Any, Any]]:
    """``(schema, channel, message)`` of every message in file order (every chunk bounded: see
    :mod:`.mcap_records`); of a file without footer (a recording cut short, e.g. by a crash)
    every complete chunk up to the cut, with a note."""
    finished = _has_footer(f)
    found = McapRecords()
    count, last = 0, None
    try:
        for item in iter_messages(f, found, limits.max_chunk_bytes, limits.max_chunk_ratio):
            count, last = count + 1, item[2].log_time
            yield item
    except DamagedError as exc:
        if finished:
            raise
        if not count:
            raise ValueError(
                f"no footer, and cut short before the first complete chunk ({exc})"
            ) from None
        notes.append(
            f"the file is cut short ({exc}); read the {count} messages before the cut "
            f"(up to log time {(last or 0) * 1e-9:.3f} s)"
        )
