"""``ZenohDisplayNode``: the robot's head screen on the bus. It listens to the engine's eye state
(``gazebot/<id>/eyes``, :class:`~gazebot.drivers.payloads.EyeStateMsg`, tens of bytes) and
reports its own heartbeat; drawing is :mod:`gazebot.render.head_display`'s."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar

from gazebot.drivers.keys import KeyLayout
from gazebot.drivers.payloads import EyeStateMsg
from gazebot.drivers.zenoh_node import ZenohNode

if TYPE_CHECKING:
    import zenoh


class ZenohDisplayNode(ZenohNode):
    """Keeps the newest eye state and when it arrived (on :attr:`clock`).

    Args:
        session: An open session (left open by :meth:`close` unless ``owns_session``).
        keys: The robot's key layout.
        node: This node's name (default ``display``).
    """

    default_node: ClassVar[str] = "display"

    def __init__(
        self,
        session: zenoh.Session,
        keys: KeyLayout,
        node: str = "display",
        *,
        owns_session: bool = False,
        peer_timeout: float = 2.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__(
            session, keys, node, owns_session=owns_session, peer_timeout=peer_timeout, clock=clock
        )
        self._eyes_lock = threading.Lock()
        self._latest: EyeStateMsg | None = None
        self._arrived = -float("inf")
        self.received = 0
        self.subscribe(keys.eyes, EyeStateMsg, self._on_eyes)
        self.announce()

    def _on_eyes(self, msg: EyeStateMsg) -> None:
        now = self.clock()
        with self._eyes_lock:  # Zenoh keeps one publisher's order: the last one is the newest
            self._latest = msg
            self._arrived = now
            self.received += 1

    def latest(self) -> tuple[EyeStateMsg | None, float]:
        """The newest eye state and its age (s; ``inf`` when none ever arrived)."""
        with self._eyes_lock:
            msg, arrived = self._latest, self._arrived
        return msg, (self.clock() - arrived) if msg is not None else float("inf")

    def status(self, eyes: str, info: dict[str, Any]) -> None:
        """Publish the display's heartbeat; ``eyes`` (``live``, ``silent``, ``waiting``) goes
        to ``info.eyes``."""
        self.heartbeat(tracking="n/a", info={"eyes": eyes, **info})
