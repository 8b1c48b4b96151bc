"""The peer of ``bench_messages``: an independent CDR implementation of the same ROS 2 messages,
mcap-ros2-support's (Foxglove's pure-Python ``CdrWriter``/``CdrReader``, the encoder and decoder
the ``mcap`` tools use for ROS 2), fed the message definitions as an MCAP file embeds them.

gazebot's own side serializes with rosbags; zenoh-ros2-sdk serializes with rosbags too, so it is
not an independent peer. Each trip here is what gazebot's is, written as a plain user of
mcap-ros2-support would: a value -> the message as nested dicts -> CDR bytes -> the decoder's
message -> the value, with the same checks (finite numbers, ranges, lengths). The bytes are the
wire's: ``bench_messages`` checks that both sides put the same bytes on it.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from functools import cache
from typing import Any

import numpy as np
from mcap_ros2._dynamic import generate_dynamic, serialize_dynamic

from gazebot.core.types import Event, EventKind, TrackingFrame
from gazebot.io.ros2.typestore import typestore

#: Decoded messages are the library's own dynamic classes: read by attribute.
Decoded = Any


@cache
def coders(type_name: str) -> tuple[Callable[[object], bytes], Callable[[bytes], Decoded]]:
    """``(encode, decode)`` of ``type_name`` by mcap-ros2-support, from its full definition."""
    text, _ = typestore().generate_msgdef(type_name, ros_version=2)
    return serialize_dynamic(type_name, text)[type_name], generate_dynamic(type_name, text)[
        type_name]


def _time(t: float) -> dict[str, int]:
    if not math.isfinite(t):
        raise ValueError(f"time is not finite: {t}")
    sec, nanosec = divmod(round(t * 1e9), 1_000_000_000)
    return {"sec": sec, "nanosec": nanosec}


def _seconds(stamp: Decoded) -> float:
    return stamp.sec + 1e-9 * stamp.nanosec


def _header(t: float, frame_id: str = "") -> dict[str, object]:
    return {"stamp": _time(t), "frame_id": frame_id}


def _finite(*values: float) -> None:
    if not all(math.isfinite(v) for v in values):
        raise ValueError(f"not finite: {values}")


def tracking_trip(frame: TrackingFrame, frame_id: str = "world") -> TrackingFrame:
    """A tracking sample as gazebot's topics carry it (one ``PointStamped`` per tracked body,
    ``GripperState``, ``LoadShare``) and back."""
    enc_p, dec_p = coders("geometry_msgs/msg/PointStamped")
    enc_g, dec_g = coders("gazebot_msgs/msg/GripperState")
    enc_s, dec_s = coders("gazebot_msgs/msg/LoadShare")
    raws = {}
    for body in ("giver_hand", "receiver_hand", "giver_face"):
        p = np.asarray(getattr(frame, body), dtype=float)
        if bool(np.all(np.isfinite(p))):
            x, y, z = (float(v) for v in p)
            raws[body] = enc_p({"header": _header(frame.t, frame_id),
                                "point": {"x": x, "y": y, "z": z}})
    grip = enc_g({"header": _header(frame.t), "closed": bool(frame.gripper_closed)})
    share = enc_s({"header": _header(frame.t), "share": float(frame.load_share or 0.0)})
    points = {}
    for body, raw in raws.items():
        msg = dec_p(raw)
        xyz = (msg.point.x, msg.point.y, msg.point.z)
        _finite(*xyz)
        points[body] = xyz
    g, s = dec_g(grip), dec_s(share)
    if not 0.0 <= s.share <= 1.0:
        raise ValueError(f"share outside 0..1: {s.share}")
    return TrackingFrame.make(_seconds(g.header.stamp), **points, gripper_closed=g.closed,
                              load_share=s.share)


def tracking_bytes(frame: TrackingFrame, frame_id: str = "world") -> list[bytes]:
    """The CDR bytes of :func:`tracking_trip`'s messages, in the order gazebot publishes them."""
    enc_p, _ = coders("geometry_msgs/msg/PointStamped")
    enc_g, _ = coders("gazebot_msgs/msg/GripperState")
    enc_s, _ = coders("gazebot_msgs/msg/LoadShare")
    out = []
    for body in ("giver_hand", "receiver_hand", "giver_face"):
        x, y, z = (float(v) for v in getattr(frame, body))
        out.append(enc_p({"header": _header(frame.t, frame_id), "point": {"x": x, "y": y, "z": z}}))
    out.append(enc_g({"header": _header(frame.t), "closed": bool(frame.gripper_closed)}))
    out.append(enc_s({"header": _header(frame.t), "share": float(frame.load_share or 0.0)}))
    return out


def head_bytes(positions: Mapping[str, float], time_from_start: float) -> bytes:
    """``head/command``: one ``JointTrajectory`` point, header stamp zero (start on receipt)."""
    enc, _ = coders("trajectory_msgs/msg/JointTrajectory")
    names = list(positions)
    pos = [float(positions[n]) for n in names]
    _finite(*pos)
    point = {"positions": pos, "velocities": [0.0] * len(pos), "accelerations": [],
             "effort": [], "time_from_start": _time(time_from_start)}
    return enc({"header": _header(0.0), "joint_names": names, "points": [point]})


def head_trip(positions: Mapping[str, float], time_from_start: float) -> dict[str, float]:
    """:func:`head_bytes` and back to the goal positions by joint."""
    _, dec = coders("trajectory_msgs/msg/JointTrajectory")
    msg = dec(head_bytes(positions, time_from_start))
    last = msg.points[-1]
    if len(last.positions) != len(msg.joint_names):
        raise ValueError("joint_names and positions differ in length")
    _finite(*last.positions)
    return dict(zip(msg.joint_names, (float(q) for q in last.positions), strict=True))


def eyes_bytes(t: float, yaw: float, pitch: float, blink: float, distance: float | None,
               frame_id: str = "gaze") -> bytes:
    """``gazebot_msgs/EyeState`` (an unknown distance is NaN)."""
    enc, _ = coders("gazebot_msgs/msg/EyeState")
    _finite(yaw, pitch, blink)
    d = math.nan if distance is None else distance
    return enc({"header": _header(t, frame_id), "yaw": yaw, "pitch": pitch, "blink": blink,
                "distance": d})


def eyes_trip(t: float, yaw: float, pitch: float, blink: float,
              distance: float | None) -> tuple[float, float, float, float, float | None]:
    """:func:`eyes_bytes` and back, checked as gazebot checks it."""
    _, dec = coders("gazebot_msgs/msg/EyeState")
    msg = dec(eyes_bytes(t, yaw, pitch, blink, distance))
    _finite(msg.yaw, msg.pitch, msg.blink)
    if not 0.0 <= msg.blink <= 1.0:
        raise ValueError(f"blink outside 0..1: {msg.blink}")
    d = None if math.isnan(msg.distance) else msg.distance
    return _seconds(msg.header.stamp), msg.yaw, msg.pitch, msg.blink, d


def event_bytes(event: Event, source: str, category: str, stamp: float) -> bytes:
    """``gazebot_msgs/HandoverEvent`` (info values as JSON text, strings as they are)."""
    enc, _ = coders("gazebot_msgs/msg/HandoverEvent")
    info = [{"key": k, "value": v if isinstance(v, str) else json.dumps(v, allow_nan=False)}
            for k, v in event.info.items()]
    return enc({"header": _header(stamp), "source": source, "category": category,
                "kind": event.kind.value, "t": _time(event.t),
                "detected_at": _time(event.detected_at), "info": info})


def event_trip(event: Event, source: str, category: str, stamp: float) -> Event:
    """:func:`event_bytes` and back to the core's event."""
    _, dec = coders("gazebot_msgs/msg/HandoverEvent")
    msg = dec(event_bytes(event, source, category, stamp))
    info: dict[str, object] = {}
    for kv in msg.info:
        try:
            info[kv.key] = json.loads(kv.value)
        except ValueError:
            info[kv.key] = kv.value
    return Event(EventKind(msg.kind), _seconds(msg.t), _seconds(msg.detected_at), info)


def image_bytes(jpeg: bytes, t: float, frame_id: str = "gaze") -> bytes:
    """``sensor_msgs/CompressedImage`` carrying encoded JPEG bytes."""
    enc, _ = coders("sensor_msgs/msg/CompressedImage")
    return enc({"header": _header(t, frame_id), "format": "jpeg", "data": jpeg})


def image_trip(jpeg: bytes, t: float) -> bytes:
    """:func:`image_bytes` and back to the encoded image."""
    _, dec = coders("sensor_msgs/msg/CompressedImage")
    return bytes(dec(image_bytes(jpeg, t)).data)
