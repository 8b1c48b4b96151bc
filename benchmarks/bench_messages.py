"""Message encode + decode: ROS 2 CDR (``gazebot.io.ros2``: rosbags' serializer, what the ROS 2 wire
sends) against the JSON payloads it replaced (``benchmarks/json_payload_peer.py``: strict pydantic
models), per message, in one run.

Each side does the whole trip a bus message makes between gazebot values: value -> message ->
bytes -> message -> value (both validate: the JSON models check types and finiteness, the CDR
side the conversions' finiteness checks). A tracking sample is one JSON message but three
``PointStamped`` plus ``GripperState`` and ``LoadShare`` on the ROS wire; eye frames carry the
same JPEG bytes (base64 inside JSON vs a uint8 sequence in ``CompressedImage``), image coding
not timed. Ours and the peer are timed in alternating rounds (medians).
"""

from __future__ import annotations

import base64
import statistics
from collections.abc import Callable
from dataclasses import dataclass, field

import cv2
import numpy as np

from benchmarks import json_payload_peer as js
from benchmarks.common import Result, median_time
from gazebot.core.types import Event, EventKind, Phase, TrackingFrame
from gazebot.io.ros2 import Codec, typestore
from gazebot.io.ros2 import convert as cv

N = 50  # messages per timed round (short rounds, interleaved: load hits both alike)
ROUNDS = 21


def _paired(ours: Callable[[], object], peer: Callable[[], object]) -> tuple[float, float]:
    """Median seconds per message of ``ours`` and ``peer``, timed in alternating rounds."""
    t_ours, t_peer = [], []
    for _ in range(ROUNDS):
        t_ours.append(median_time(ours, repeat=1, number=N, warmup=1))
        t_peer.append(median_time(peer, repeat=1, number=N, warmup=1))
    return statistics.median(t_ours), statistics.median(t_peer)


def _codec(name: str) -> Codec:
    return Codec.for_type(typestore(), name)


def _tracking() -> tuple[Callable[[], object], Callable[[], object], int, int]:
    frame = TrackingFrame.make(1.25, [0.61, 0.02, 1.05], [0.72, -0.1, 1.0], [1.2, 0.05, 1.6],
                               gripper_closed=True, load_share=0.5)
    point, grip, load = _codec(cv.POINT_STAMPED), _codec(cv.GRIPPER_STATE), _codec(cv.LOAD_SHARE)

    def ours() -> TrackingFrame:
        raws = [point.encode(cv.point_stamped(frame.t, p, "world"))
                for p in cv.tracking_points(frame).values()]
        g = grip.encode(cv.gripper_state(frame.t, bool(frame.gripper_closed)))
        s = load.encode(cv.load_share(frame.t, float(frame.load_share)))
        points = {b: cv.point_of(point.decode(r))[1] for b, r in zip(cv.BODIES, raws, strict=True)}
        closed = grip.decode(g).closed
        _, share = cv.share_of(load.decode(s))
        return cv.tracking_frame(frame.t, points, closed, share)

    def peer() -> TrackingFrame:
        raw = js.TrackingMsg.from_frame(frame, seq=7, stamp=1.7e9).encode()
        return js.TrackingMsg.decode(raw).to_frame()

    ours_bytes = sum(len(point.encode(cv.point_stamped(1.0, [0, 0, 0], "world"))) for _ in range(3))
    ours_bytes += len(grip.encode(cv.gripper_state(1.0, True)))
    ours_bytes += len(load.encode(cv.load_share(1.0, 0.5)))
    return ours, peer, ours_bytes, len(js.TrackingMsg.from_frame(frame, 7, 1.7e9).encode())


@dataclass(frozen=True)
class _Command:
    """The engine command's attributes both sides read."""

    t: float = 2.5
    phase: Phase = Phase.REACH
    target: str = "hand"
    target_point: np.ndarray = field(default_factory=lambda: np.array([0.6, 0.0, 1.05]))
    head: dict = field(default_factory=lambda: {"head_pan": 0.31})
    eye_yaw: float = 0.05
    eye_pitch: float = -0.02
    blink: float = 0.0
    distance: float | None = 0.9
    residual: float = 0.01


def _command() -> _Command:
    return _Command()


def _head() -> tuple[Callable[[], object], Callable[[], object], int, int]:
    cmd = _command()
    codec = _codec(cv.JOINT_TRAJECTORY)

    def ours() -> object:
        return cv.trajectory_goal(codec.decode(codec.encode(cv.head_trajectory(cmd, 1 / 120))))

    def peer() -> object:
        raw = js.HeadCommandMsg.from_command(cmd, seq=7, stamp=1.7e9, answers=6).encode()
        return js.HeadCommandMsg.decode(raw).head

    return (ours, peer, len(codec.encode(cv.head_trajectory(cmd, 1 / 120))),
            len(js.HeadCommandMsg.from_command(cmd, 7, 1.7e9, 6).encode()))


def _eyes() -> tuple[Callable[[], object], Callable[[], object], int, int]:
    cmd = _command()
    codec = _codec(cv.EYE_STATE)

    def ours() -> object:
        return cv.eyes_of(codec.decode(codec.encode(cv.eye_state(cmd, "gaze"))))

    def make_peer() -> js.EyeStateMsg:
        return js.EyeStateMsg(seq=7, t=cmd.t, stamp=1.7e9, yaw=cmd.eye_yaw, pitch=cmd.eye_pitch,
                              blink=cmd.blink, distance=cmd.distance)

    def peer() -> object:
        return js.EyeStateMsg.decode(make_peer().encode())

    return ours, peer, len(codec.encode(cv.eye_state(cmd, "gaze"))), len(make_peer().encode())


def _event() -> tuple[Callable[[], object], Callable[[], object], int, int]:
    event = Event(EventKind.ROBOT_REACH_STARTED, 1.0, 1.02, {"planned_duration": 1.2})
    codec = _codec(cv.HANDOVER_EVENT)

    def ours() -> object:
        return cv.event_of(codec.decode(codec.encode(cv.event_msg(event, "sim", 1.02)))).to_event()

    def peer() -> object:
        raw = js.EventMsg.from_event(event, "sim", seq=3, stamp=1.7e9).encode()
        return js.EventMsg.decode(raw).to_event()

    return (ours, peer, len(codec.encode(cv.event_msg(event, "sim", 1.02))),
            len(js.EventMsg.from_event(event, "sim", 3, 1.7e9).encode()))


def _eye_frame() -> tuple[Callable[[], object], Callable[[], object], int, int]:
    from gazebot.apps.render import EyeRenderer

    img = EyeRenderer.for_robot("sawyer").render(0.1, -0.05)
    ok, buf = cv2.imencode(".jpg", img[:, :, ::-1])
    assert ok
    jpeg = buf.tobytes()
    h, w = img.shape[:2]
    codec = _codec(cv.COMPRESSED_IMAGE)
    store = typestore()
    header = cv.header(1.0, "display", store)

    def make_ours() -> object:
        return store.types[cv.COMPRESSED_IMAGE](
            header=header, format="jpeg", data=np.frombuffer(jpeg, np.uint8))

    def ours() -> bytes:
        return codec.decode(codec.encode(make_ours())).data.tobytes()

    def make_peer() -> js.EyeFrameMsg:
        return js.EyeFrameMsg(seq=1, t=1.0, stamp=1.7e9, width=w, height=h, format="jpeg",
                              data=base64.b64encode(jpeg).decode("ascii"))

    def peer() -> bytes:
        return base64.b64decode(js.EyeFrameMsg.decode(make_peer().encode()).data, validate=True)

    assert ours() == peer() == jpeg
    return ours, peer, len(codec.encode(make_ours())), len(make_peer().encode())


def run() -> list[Result]:
    results = []
    for name, make in (("tracking sample", _tracking), ("head command", _head),
                       ("eye state", _eyes), ("handover event", _event),
                       ("eye frame (JPEG)", _eye_frame)):
        ours, peer, ours_bytes, peer_bytes = make()
        t_ours, t_peer = _paired(ours, peer)
        results.append(Result(
            f"{name}: encode + decode", t_ours * 1e6, t_peer * 1e6, "us", "JSON payload",
            note=f"{ours_bytes} B CDR vs {peer_bytes} B JSON",
        ))
    return results
