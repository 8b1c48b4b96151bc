"""Message encode + decode, per ROS 2 message gazebot puts on the bus: gazebot's conversions with
rosbags' CDR serializer (``gazebot.io.ros2``) against an independent CDR implementation of the
same messages, mcap-ros2-support's (``benchmarks/cdr_peer.py``), in one run.

Each side does the whole trip a bus message makes between gazebot values: value -> message ->
bytes -> message -> value, with the same checks (finite numbers, ranges, lengths). A tracking
sample is three ``PointStamped`` plus ``GripperState`` and ``LoadShare``; an eye frame carries
the same JPEG bytes (image coding not timed). Before timing, both sides' bytes are checked to
be the same: the peer is a second implementation of the same wire. Ours and the peer are timed in
alternating rounds (medians).
"""

from __future__ import annotations

import statistics
from collections.abc import Callable

import cv2
import numpy as np

from benchmarks import cdr_peer as peer_cdr
from benchmarks.common import Result, median_time
from gazebot.core.types import Event, EventKind, GazeCommand, Phase, TrackingFrame
from gazebot.io.ros2 import Codec, typestore
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2.values import BusEvent, EyeState, JointGoal

N = 50  # messages per timed round (short rounds, interleaved: load hits both alike)
ROUNDS = 21

Case = tuple[Callable[[], object], Callable[[], object], int]


def _paired(ours: Callable[[], object], peer: Callable[[], object]) -> tuple[float, float]:
    """Median seconds per message of ``ours`` and ``peer``, timed in alternating rounds."""
    t_ours, t_peer = [], []
    for _ in range(ROUNDS):
        t_ours.append(median_time(ours, repeat=1, number=N, warmup=1))
        t_peer.append(median_time(peer, repeat=1, number=N, warmup=1))
    return statistics.median(t_ours), statistics.median(t_peer)


def _codec(name: str) -> Codec:
    return Codec.for_type(typestore(), name)


def _same_wire(ours: list[bytes], peer: list[bytes]) -> int:
    """Both sides' bytes, checked equal; their total size."""
    if ours != peer:
        raise AssertionError("gazebot and the peer put different bytes on the wire")
    return sum(len(b) for b in ours)


def _tracking() -> Case:
    frame = TrackingFrame.make(1.25, [0.61, 0.02, 1.05], [0.72, -0.1, 1.0], [1.2, 0.05, 1.6],
                               gripper_closed=True, load_share=0.5)
    point, grip, load = _codec(cv.POINT_STAMPED), _codec(cv.GRIPPER_STATE), _codec(cv.LOAD_SHARE)

    def encode() -> list[bytes]:
        raws = [point.encode(cv.point_stamped(frame.t, p, "world"))
                for p in cv.tracking_points(frame).values()]
        raws.append(grip.encode(cv.gripper_state(frame.t, bool(frame.gripper_closed))))
        raws.append(load.encode(cv.load_share(frame.t, float(frame.load_share or 0.0))))
        return raws

    def ours() -> TrackingFrame:
        *raws, g, s = encode()
        points = {b: cv.point_of(point.decode(r))[1] for b, r in zip(cv.BODIES, raws, strict=True)}
        closed = grip.decode(g).closed
        _, share = cv.share_of(load.decode(s))
        return cv.tracking_frame(frame.t, points, closed, share)

    def peer() -> TrackingFrame:
        return peer_cdr.tracking_trip(frame)

    return ours, peer, _same_wire(encode(), peer_cdr.tracking_bytes(frame))


def _command() -> GazeCommand:
    return GazeCommand(t=2.5, phase=Phase.REACH, target="hand",
                       target_point=np.array([0.6, 0.0, 1.05]), head={"head_pan": 0.31},
                       eye_yaw=0.05, eye_pitch=-0.02, distance=0.9)


def _head() -> Case:
    cmd = _command()
    codec = _codec(cv.JOINT_TRAJECTORY)

    def encode() -> bytes:
        return codec.encode(cv.joint_trajectory(JointGoal.head_of(cmd)))

    def ours() -> object:
        return cv.trajectory_goal(codec.decode(encode())).positions

    def peer() -> object:
        return peer_cdr.head_trip(cmd.head, 1 / 120)

    return ours, peer, _same_wire([encode()], [peer_cdr.head_bytes(cmd.head, 1 / 120)])


def _eyes() -> Case:
    cmd = _command()
    codec = _codec(cv.EYE_STATE)

    def encode() -> bytes:
        return codec.encode(cv.eye_state(EyeState.of(cmd), "gaze"))

    def ours() -> object:
        return cv.eyes_of(codec.decode(encode()))

    def peer() -> object:
        return peer_cdr.eyes_trip(cmd.t, cmd.eye_yaw, cmd.eye_pitch, cmd.blink, cmd.distance)

    wire = peer_cdr.eyes_bytes(cmd.t, cmd.eye_yaw, cmd.eye_pitch, cmd.blink, cmd.distance)
    return ours, peer, _same_wire([encode()], [wire])


def _event() -> Case:
    event = Event(EventKind.ROBOT_REACH_STARTED, 1.0, 1.02, {"planned_duration": 1.2})
    codec = _codec(cv.HANDOVER_EVENT)

    def encode() -> bytes:
        return codec.encode(cv.handover_event(BusEvent.of(event, "sim", 1.02)))

    def ours() -> object:
        return cv.event_of(codec.decode(encode())).to_event()

    def peer() -> object:
        return peer_cdr.event_trip(event, "sim", "robot", 1.02)

    return ours, peer, _same_wire([encode()], [peer_cdr.event_bytes(event, "sim", "robot", 1.02)])


def _eye_frame() -> Case:
    from gazebot.apps.render import EyeRenderer

    img = EyeRenderer.for_robot("sawyer").render(0.1, -0.05)
    ok, buf = cv2.imencode(".jpg", img[:, :, ::-1])
    assert ok
    jpeg = buf.tobytes()
    codec = _codec(cv.COMPRESSED_IMAGE)

    def encode() -> bytes:
        msg = cv.RosCompressedImage(cv.header(1.0, "gaze"), "jpeg", np.frombuffer(jpeg, np.uint8))
        return codec.encode(msg)

    def ours() -> bytes:
        return codec.decode(encode()).data.tobytes()

    def peer() -> bytes:
        return peer_cdr.image_trip(jpeg, 1.0)

    assert ours() == peer() == jpeg
    return ours, peer, _same_wire([encode()], [peer_cdr.image_bytes(jpeg, 1.0)])


def run() -> list[Result]:
    results = []
    for name, make in (("tracking sample", _tracking), ("head command", _head),
                       ("eye state", _eyes), ("handover event", _event),
                       ("eye frame (JPEG)", _eye_frame)):
        ours, peer, size = make()
        t_ours, t_peer = _paired(ours, peer)
        results.append(Result(
            f"{name}: encode + decode", t_ours * 1e6, t_peer * 1e6, "us",
            "mcap-ros2-support CDR", note=f"{size} B CDR, the same bytes both sides",
        ))
    return results
