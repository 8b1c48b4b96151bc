"""Fakes and bus helpers for the driver tests: a tiny engine with GazeEngine's interface (so the
transport is tested on its own), free loopback ports and a recorder of one topic's messages."""

from __future__ import annotations

import math
import socket
import time
from collections.abc import Callable
from types import SimpleNamespace

import numpy as np

from gazebot.core.types import Event, EventKind, GazeCommand, Phase, TrackingFrame, is_valid_point

PAN_LIMIT = 1.3


class Recorder:
    """Collects the messages of one topic from a plain Zenoh subscriber on the node's session,
    decoded as its ROS type and passed through ``convert`` (a list result is spread)."""

    def __init__(self, node, topic, convert: Callable = lambda m: m) -> None:
        from gazebot.io.ros2.codec import Codec
        from gazebot.io.ros2.typestore import typestore

        codec = Codec.for_type(typestore(), topic.type)
        resolved = node.names.resolve(topic.name)
        self.key = node.names.key(resolved, codec.info.dds_name, codec.info.hash)
        self.msgs: list = []

        from gazebot.io.ros2.errors import MessageError

        def on(sample) -> None:
            try:  # garbage a test puts on the topic is not the recorder's business
                out = convert(codec.decode(sample.payload.to_bytes()))
            except MessageError:
                return
            self.msgs.extend(out if isinstance(out, list) else [out])

        self._sub = node.session.declare_subscriber(self.key, on)

    def where(self, **kw) -> list:
        return [m for m in self.msgs if all(getattr(m, k) == v for k, v in kw.items())]


def free_port() -> int:
    """A TCP port on 127.0.0.1 nobody listens on right now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_until(pred: Callable[[], object], timeout: float = 30.0, poll: float = 0.005) -> bool:
    """Poll ``pred`` until it is truthy or ``timeout`` s passed; returns its last truthiness.

    The deadline is generous on purpose: it only bounds a failing test, and a busy 2-core CI
    machine can stall a thread for seconds."""
    end = time.monotonic() + timeout
    while True:
        if pred():
            return True
        if time.monotonic() >= end:
            return False
        time.sleep(poll)


class FakeGaze:
    """Pan-only head pointing straight at the target (no dynamics)."""

    def __init__(self) -> None:
        self.head = {"head_pan": 0.0}
        self.targets: list[tuple[float, np.ndarray]] = []

    def update(self, t: float, point: np.ndarray) -> SimpleNamespace:
        self.targets.append((t, np.asarray(point, float)))
        if is_valid_point(point):
            pan = float(np.clip(math.atan2(point[1], point[0]), -PAN_LIMIT, PAN_LIMIT))
            self.head = {"head_pan": pan}
        return SimpleNamespace(head=dict(self.head), eye_yaw=0.0, eye_pitch=0.0, residual=0.0)


class FakeClock:
    """A monotonic clock the test moves by hand (peer timeouts without wall-clock races)."""

    def __init__(self, now: float = 0.0) -> None:
        self.now = now

    def __call__(self) -> float:
        return self.now


class FakeEyes:
    def clip(self, yaw: float, pitch: float) -> tuple[float, float, bool]:
        return yaw, pitch, False


class FakeRobot:
    """Pan-only head whose ``gaze`` frame sits 1.5 m above the base."""

    name = "fake"
    head_joints = ["head_pan"]
    lower = np.array([-PAN_LIMIT])
    upper = np.array([PAN_LIMIT])
    rest = np.array([0.0])
    eyes = FakeEyes()

    def __init__(self) -> None:
        self.points = {"face": np.array([1.0, 0.0, 1.5])}

    def gaze_frame_lists(self, q) -> list[list[float]]:
        return [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 1.5]]


class FakeEngine:
    """Looks at the face; ``reach_started`` when the giver's hand comes closer than 0.7 m.

    A step without any tracked point counts as tracking lost at once (``hold`` for 0.1 s, then
    ``lost``), looking at the last face meanwhile."""

    def __init__(self) -> None:
        self.robot = FakeRobot()
        self.lost_since: float | None = None
        self.last_t = 0.0
        self.gaze = FakeGaze()
        self.behavior = SimpleNamespace(state="start")
        self.phase = Phase.IDLE
        self.notified: list[Event] = []
        self.resynced: list[Event] = []
        self.reset_heads: list[dict | None] = []
        self.frames: list[TrackingFrame] = []
        self._face = self.robot.points["face"]

    @property
    def tracking(self) -> str:
        if self.lost_since is None:
            return "ok"
        return "hold" if self.last_t < self.lost_since + 0.1 else "lost"

    def step(self, frame: TrackingFrame, arm: dict | None = None) -> GazeCommand:
        self.frames.append(frame)
        self.last_t = frame.t
        events = []
        tracked = is_valid_point(frame.giver_hand) or is_valid_point(frame.giver_face)
        if not tracked and self.lost_since is None:
            self.lost_since = frame.t
            events.append(Event(EventKind.TRACKING_LOST, frame.t, frame.t))
        elif tracked and self.lost_since is not None:
            self.lost_since = None
            events.append(Event(EventKind.TRACKING_RESTORED, frame.t, frame.t))
        if (
            self.phase == Phase.IDLE
            and is_valid_point(frame.giver_hand)
            and frame.giver_hand[0] < 0.7
        ):
            self.phase = Phase.REACH
            self.behavior.state = "reach"
            events.append(Event(EventKind.REACH_STARTED, frame.t, frame.t))
        if is_valid_point(frame.giver_face):
            self._face = frame.giver_face
        st = self.gaze.update(frame.t, self._face)
        return GazeCommand(
            t=frame.t, phase=self.phase, target="face", target_point=self._face, head=st.head,
            eye_yaw=0.0, eye_pitch=0.0, events=tuple(events), tracking=self.tracking,
        )

    def notify(self, event: Event) -> None:
        self.notified.append(event)

    def resync(self, events: list[Event]) -> None:
        self.resynced.extend(events)
        for e in events:
            if e.kind == EventKind.REACH_STARTED:
                self.phase = Phase.REACH
            elif e.kind == EventKind.TRANSFER_STARTED:
                self.phase = Phase.TRANSFER

    def reset(self, head: dict | None = None) -> None:
        self.reset_heads.append(head)
        self.phase = Phase.IDLE
        self.lost_since = None
        if head:
            self.gaze.head = dict(head)
