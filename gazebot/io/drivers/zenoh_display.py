"""``ZenohDisplayNode``: the robot's head screen on the bus. It listens to the engine's eye state
(``eyes/state``, ``gazebot_msgs/msg/EyeState``, under 100 bytes) and reports its own heartbeat;
drawing is :mod:`gazebot.apps.render.head_display`'s."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, ClassVar

from gazebot.io.drivers.rmw.names import Names
from gazebot.io.drivers.rmw.node import Received
from gazebot.io.drivers.zenoh_node import ZenohNode
from gazebot.io.ros2 import convert, topics
from gazebot.io.ros2.convert import RosEyeState
from gazebot.io.ros2.values import EyeState, Json

if TYPE_CHECKING:
    import zenoh


class ZenohDisplayNode(ZenohNode):
    """Keeps the newest eye state and when it arrived (on :attr:`clock`).

    Args:
        session: An open session (left open by :meth:`close` unless ``owns_session``).
        names: Namespace, remapping, domain id and frame names.
        node: This node's name (default ``display``).
    """

    default_node: ClassVar[str] = "display"

    def __init__(
        self,
        session: zenoh.Session,
        names: Names,
        node: str = "display",
        *,
        owns_session: bool = False,
        peer_timeout: float = 2.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__(
            session, names, node, owns_session=owns_session, peer_timeout=peer_timeout, clock=clock
        )
        self._eyes_lock = threading.Lock()
        self._latest: EyeState | None = None
        self._arrived = -float("inf")
        self.received = 0
        self.ros.subscription(topics.EYES.name, topics.EYES.type, self._on_eyes)
        self.announce()

    def _on_eyes(self, ros: RosEyeState, rx: Received) -> None:
        msg = convert.eyes_of(ros)
        now = self.clock()
        with self._eyes_lock:  # Zenoh keeps one publisher's order: the last one is the newest
            self._latest = msg
            self._arrived = now
            self.received += 1

    def latest(self) -> tuple[EyeState | None, float]:
        """The newest eye state and its age (s; ``inf`` when none ever arrived)."""
        with self._eyes_lock:
            msg, arrived = self._latest, self._arrived
        return msg, (self.clock() - arrived) if msg is not None else float("inf")

    def status(self, eyes: str, info: dict[str, Json]) -> None:
        """Publish the display's heartbeat; ``eyes`` (``live``, ``silent``, ``waiting``) goes
        to ``info.eyes``."""
        self.heartbeat(tracking="n/a", info={"eyes": eyes, **info})
