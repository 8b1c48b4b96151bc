"""``ZenohRobotEndpoint``: the robot side of the bus (a simulator node or a real robot's bridge):
publishes tracking, joint states and robot events; receives head, eye and arm commands."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, ClassVar, Generic, TypeVar

from gazebot.drivers.keys import KeyLayout
from gazebot.drivers.payloads import (
    ArmCommandMsg,
    EventMsg,
    EyeFrameMsg,
    EyeStateMsg,
    HeadCommandMsg,
    JointStateMsg,
    Msg,
    TrackingMsg,
)
from gazebot.drivers.zenoh_node import ZenohNode
from gazebot.types import Event, TrackingFrame

if TYPE_CHECKING:
    import zenoh

M = TypeVar("M", bound=Msg)


class Latest(Generic[M]):
    """The newest message of one kind; :meth:`take` returns it once."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._msg: M | None = None
        self._fresh = False
        self.count = 0

    def put(self, msg: M) -> None:
        with self._lock:
            self._msg, self._fresh = msg, True
            self.count += 1

    def take(self) -> M | None:
        """The newest message if not taken before, else ``None``."""
        with self._lock:
            if not self._fresh:
                return None
            self._fresh = False
            return self._msg

    def peek(self) -> M | None:
        with self._lock:
            return self._msg


class ZenohRobotEndpoint(ZenohNode):
    """The robot's side of the bus.

    Args:
        session: An open session (closed by :meth:`close` only if ``owns_session``).
        keys: The robot's key layout.
        node: This node's name (default ``sim``).
        eye_frames: Subscribe to rendered eye frames. The engine renders frames only while
            someone subscribes, so a robot that draws its eyes from the eye state leaves this off.
    """

    default_node: ClassVar[str] = "sim"

    def __init__(
        self,
        session: zenoh.Session,
        keys: KeyLayout,
        node: str = "sim",
        *,
        owns_session: bool = False,
        eye_frames: bool = False,
        peer_timeout: float = 2.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__(
            session, keys, node, owns_session=owns_session, peer_timeout=peer_timeout, clock=clock
        )
        self._tracking_seq = 0
        self._joint_seq = 0
        self.head: Latest[HeadCommandMsg] = Latest()
        self.eyes: Latest[EyeStateMsg] = Latest()
        self.eye_frame: Latest[EyeFrameMsg] = Latest()
        self.arm: Latest[ArmCommandMsg] = Latest()
        self._tracking_pub = self._declare(session.declare_publisher(keys.tracking))
        self._joints_pub = self._declare(session.declare_publisher(keys.joint_states))
        self.subscribe(keys.head_command, HeadCommandMsg, self.head.put)
        self.subscribe(keys.eyes, EyeStateMsg, self.eyes.put)
        if eye_frames:
            self.subscribe(keys.eyes_frame, EyeFrameMsg, self.eye_frame.put)
        self.subscribe(keys.arm_command, ArmCommandMsg, self.arm.put)
        self.announce()

    def publish_tracking(self, frame: TrackingFrame) -> TrackingMsg:
        """Publish one tracking sample (numbered) and return it."""
        msg = TrackingMsg.from_frame(frame, self._tracking_seq, time.time())
        self._tracking_seq += 1
        self.put(self._tracking_pub, msg)
        return msg

    def publish_joint_state(self, t: float, position: Mapping[str, float]) -> JointStateMsg:
        """Publish the measured joint positions (rad or m, by joint name)."""
        msg = JointStateMsg(
            seq=self._joint_seq,
            t=float(t),
            stamp=time.time(),
            position={k: float(v) for k, v in position.items()},
        )
        self._joint_seq += 1
        self.put(self._joints_pub, msg)
        return msg

    def publish_robot_event(self, event: Event) -> EventMsg:
        """Publish an event of the robot's own controller (``robot_reach_started``, ...)."""
        msg = EventMsg.from_event(event, self.node, self.next_event_seq(), time.time())
        self.publish_event(msg)
        return msg
