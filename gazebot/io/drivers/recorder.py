"""``BusRecorder``: record gazebot's topics from the bus to MCAP, as ``ros2 bag record`` does: a
node (``recorder``) that subscribes to every topic of :data:`gazebot.io.ros2.topics.ALL` (eye
images only when asked: subscribing to them makes the engine render them) and stores the CDR
bytes it receives, with ROS 2 schemas embedded
(:class:`~gazebot.io.ros2.mcap_writer.McapRecorder`). Log time is the receive time (wall clock,
ns), as rosbag2's.

The file is written under its final name from the start and flushed at least once per
``flush_period`` (a timer thread writes the chunk in progress even when the bus goes quiet), so
a recorder killed at any moment loses at most about that much; nothing is kept per message
beyond the chunk in progress.
"""

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
from gazebot.io.ros2.mcap_writer import FLUSH_PERIOD_S, McapRecorder, Split

if TYPE_CHECKING:
    import zenoh

log = logging.getLogger("gazebot.io.drivers")


class BusRecorder:
    """Record the bus of one namespace to ``path``.

    Args:
        session: An open Zenoh session (left open).
        names: Namespace, remapping and domain id of the topics.
        path: The ``.mcap`` file (with a splitting ``split``: ``NAME_0.mcap``, ``NAME_1.mcap``,
            ...). eye_images: Also record ``eyes/image/compressed``.
        split: When to go on to the next file (default: never).
        flush_period: Seconds between flushes of the file (what a kill loses at most).
    """

    def __init__(self, session: zenoh.Session, names: Names, path: str | Path, *,
                 eye_images: bool = False, split: Split | None = None,
                 flush_period: float = FLUSH_PERIOD_S) -> None:
        self.path = Path(path)
        self.mcap: McapRecorder | None = McapRecorder(self.path, split=split,
                                                      flush_period=flush_period)
        self._lock = threading.Lock()
        self._recorded = 0
        self._files: list[Path] = []
        self._stop = threading.Event()
        self._flusher = threading.Thread(target=self._flush_loop, args=(flush_period,),
                                         name="gazebot-recorder-flush", daemon=True)
        self._flusher.start()
        self.node = RosNode(session, names, "recorder")
        for topic in topics.ALL:
            if topic is topics.EYE_IMAGE and not eye_images:
                continue
            self.node.subscription(topic.name, topic.type, self._on, raw=True)
        self.node.announce()

    def _flush_loop(self, period: float) -> None:
        # Every period, whatever arrived: a message waits at most one period to be written.
        while not self._stop.wait(period):
            with self._lock:
                if self.mcap is not None:
                    try:
                        self.mcap.flush()
                    except OSError as exc:  # a full disk: said once per period, kept trying
                        log.error("recording %s: cannot write: %s", self.path, exc)

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

    @property
    def files(self) -> list[Path]:
        """The files written so far (one unless the recording splits)."""
        with self._lock:
            return list(self.mcap.files) if self.mcap is not None else list(self._files)

    def close(self) -> Path:
        """Stop recording and finish the file; returns its path (the last one of a split
        recording: all in :attr:`files`)."""
        self.node.close()
        self._stop.set()
        if self._flusher.is_alive() and self._flusher is not threading.current_thread():
            self._flusher.join()
        with self._lock:
            mcap, self.mcap = self.mcap, None
            if mcap is not None:
                self._recorded = mcap.messages
                self._files = list(mcap.files)
        if mcap is not None:
            return mcap.close()
        return self._files[-1] if self._files else self.path
