"""``BusRecorder``: record gazebot's topics from the bus to MCAP, as ``ros2 bag record`` does: a
node (``recorder``) that subscribes to every topic of :data:`gazebot.io.ros2.topics.ALL` (eye
images only when asked: subscribing to them makes the engine render them) and stores the CDR
bytes it receives, with ROS 2 schemas embedded
(:class:`~gazebot.io.ros2.mcap_writer.McapRecorder`). Log time is the receive time (wall clock,
ns), as rosbag2's."""

from __future__ import annotations

import logging
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING

from gazebot.io.drivers.rmw.names import Names
from gazebot.io.drivers.rmw.node import Received, RosNode
from gazebot.io.ros2 import topics
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.mcap_writer import McapRecorder

if TYPE_CHECKING:
    import zenoh

log = logging.getLogger("gazebot.io.drivers")


class BusRecorder:
    """Record the bus of one namespace to ``path``.

    Args:
        session: An open Zenoh session (left open).
        names: Namespace, remapping and domain id of the topics.
        path: The ``.mcap`` file (written beside and moved into place by :meth:`close`).
        eye_images: Also record ``eyes/image/compressed``.
    """

    def __init__(self, session: zenoh.Session, names: Names, path: str | Path, *,
                 eye_images: bool = False) -> None:
        self.path = Path(path)
        self.mcap: McapRecorder | None = McapRecorder(self.path)
        self._lock = threading.Lock()
        self._recorded = 0
        self.node = RosNode(session, names, "recorder")
        for topic in topics.ALL:
            if topic is topics.EYE_IMAGE and not eye_images:
                continue
            self.node.subscription(topic.name, topic.type, self._on, raw=True)
        self.node.announce()

    def _on(self, data: bytes, rx: Received) -> None:
        with self._lock:
            if self.mcap is None:
                return
            try:
                self.mcap.write_cdr(rx.topic, rx.type, data, time.time())
            except MessageError as exc:  # checked on arrival already; a race with close()
                log.warning("not recorded on %s: %s", rx.topic, exc)

    @property
    def messages(self) -> int:
        """Messages recorded so far."""
        with self._lock:
            return self.mcap.messages if self.mcap is not None else self._recorded

    def close(self) -> Path:
        """Stop recording and finish the file; returns its path."""
        self.node.close()
        with self._lock:
            mcap, self.mcap = self.mcap, None
            if mcap is not None:
                self._recorded = mcap.messages
        return mcap.close() if mcap is not None else self.path
