"""``ZenohRobotDriver``: drive any robot whose bridge speaks gazebot's keys on a Zenoh bus."""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, ClassVar

from gazebot.drivers.base import RobotDriver
from gazebot.drivers.keys import KeyLayout
from gazebot.drivers.payloads import (
    ArmCommandMsg,
    EyeFrameMsg,
    EyeStateMsg,
    HeadCommandMsg,
    JointStateMsg,
    TrackingMsg,
)
from gazebot.drivers.zenoh_node import ZenohNode

if TYPE_CHECKING:
    import zenoh


class ZenohRobotDriver(ZenohNode, RobotDriver):
    """The engine side of the bus: publishes head/eyes/arm commands, events and heartbeats;
    receives tracking, joint states, the robot's events and heartbeats.

    Args:
        session: An open session (left open by :meth:`close` unless ``owns_session``).
        keys: The robot's key layout.
        node: This node's name (default ``engine``).
        owns_session: Close ``session`` in :meth:`close` (set by :meth:`open`).
        peer_timeout: Heartbeat timeout (s) after which a peer counts as lost.
        tracking_backlog: Unread tracking samples kept (oldest dropped beyond, counted in
            ``tracking_skipped``): 12 = 0.1 s at 120 Hz, the most the engine may lag.
    """

    default_node: ClassVar[str] = "engine"

    def __init__(
        self,
        session: zenoh.Session,
        keys: KeyLayout,
        node: str = "engine",
        *,
        owns_session: bool = False,
        peer_timeout: float = 2.0,
        tracking_backlog: int = 12,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__(
            session, keys, node, owns_session=owns_session, peer_timeout=peer_timeout, clock=clock
        )
        self._cond = threading.Condition(threading.Lock())
        self._queue: deque[TrackingMsg] = deque()
        self.tracking_backlog = tracking_backlog
        self.tracking_received = 0
        self.tracking_skipped = 0
        self._joints: JointStateMsg | None = None
        self._head_pub = self._declare(session.declare_publisher(keys.head_command))
        self._eyes_pub = self._declare(session.declare_publisher(keys.eyes))
        self._frame_pub = self._declare(session.declare_publisher(keys.eyes_frame))
        self._arm_pub = self._declare(session.declare_publisher(keys.arm_command))
        self.subscribe(keys.tracking, TrackingMsg, self._on_tracking)
        self.subscribe(keys.joint_states, JointStateMsg, self._on_joints)
        self.announce()

    def _on_tracking(self, msg: TrackingMsg) -> None:
        with self._cond:
            if len(self._queue) >= self.tracking_backlog:
                self._queue.popleft()
                self.tracking_skipped += 1
            self._queue.append(msg)
            self.tracking_received += 1
            self._cond.notify_all()

    def _on_joints(self, msg: JointStateMsg) -> None:
        self._joints = msg

    # -- RobotDriver -----------------------------------------------------------------------
    def wait_tracking(self, timeout: float) -> TrackingMsg | None:
        with self._cond:
            if not self._queue:
                self._cond.wait(max(0.0, timeout))
            return self._queue.popleft() if self._queue else None

    def joint_state(self) -> JointStateMsg | None:
        return self._joints

    def send_head(self, msg: HeadCommandMsg) -> None:
        self.put(self._head_pub, msg)

    def send_eyes(self, msg: EyeStateMsg) -> None:
        self.put(self._eyes_pub, msg)

    def send_eye_frame(self, msg: EyeFrameMsg) -> None:
        self.put(self._frame_pub, msg)

    def wants_eye_frames(self) -> bool:
        # Rendering and encoding frames is costly: only while someone subscribes to them.
        return not self.closed and bool(self._frame_pub.matching_status.matching)

    def send_arm(self, msg: ArmCommandMsg) -> None:
        self.put(self._arm_pub, msg)

    def close(self) -> None:
        if self.closed:
            return
        super().close()
        with self._cond:
            self._cond.notify_all()  # wake a wait_tracking() in progress
