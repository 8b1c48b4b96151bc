"""A bounded log of events: at most ``max_events`` events and ``max_bytes`` bytes in all, the
oldest dropped first, each event at most ``max_event_bytes`` (a larger one is not kept and is
counted). A node's event history and inbox are such logs, so no peer can make a node keep more
than a few MB whatever it publishes (the event topics' size cap refuses larger messages
before they are decoded; this bounds what is kept of the ones that pass)."""

from __future__ import annotations

import json
from collections import deque
from collections.abc import Iterator

from gazebot.io.ros2.values import BusEvent

#: Bytes an event takes besides its text fields (times, sequence number, container).
_OVERHEAD = 64


def event_bytes(msg: BusEvent) -> int:
    """The size an event is counted with: its text fields and its info as JSON (UTF-8)."""
    text = msg.source + msg.category + msg.kind
    info = json.dumps(msg.info, separators=(",", ":"), default=str)
    return _OVERHEAD + len(text.encode()) + len(info.encode())


class EventLog:
    """Events in arrival order, bounded in number and bytes (not thread-safe: the node holds
    its lock).

    Args:
        max_events: Events kept at most.
        max_bytes: Total :func:`event_bytes` kept at most.
        max_event_bytes: An event larger than this is not kept (counted in :attr:`refused`).
        unique: Keep an event (by :attr:`BusEvent.identity`) only once.
    """

    def __init__(self, max_events: int = 1000, max_bytes: int = 2 * 1024 * 1024,
                 max_event_bytes: int = 16 * 1024, unique: bool = False) -> None:
        for name, value in (("max_events", max_events), ("max_bytes", max_bytes),
                            ("max_event_bytes", max_event_bytes)):
            if not isinstance(value, int) or value <= 0:
                raise ValueError(f"EventLog.{name} must be a positive integer, got {value!r}")
        self.max_events = max_events
        self.max_bytes = max_bytes
        self.max_event_bytes = min(max_event_bytes, max_bytes)
        self.unique = unique
        self.refused = 0
        self.evicted = 0
        self._events: deque[tuple[BusEvent, int]] = deque()
        self._keys: set[tuple[str, str, int, int]] = set()
        self._bytes = 0

    def append(self, msg: BusEvent) -> bool:
        """Keep ``msg`` (dropping the oldest as needed); ``False`` when it is not kept (too
        large, or already kept when :attr:`unique`)."""
        if self.unique and msg.identity in self._keys:
            return False
        size = event_bytes(msg)
        if size > self.max_event_bytes:
            self.refused += 1
            return False
        while self._events and (len(self._events) >= self.max_events
                                or self._bytes + size > self.max_bytes):
            old, old_size = self._events.popleft()
            self._bytes -= old_size
            self._keys.discard(old.identity)
            self.evicted += 1
        self._events.append((msg, size))
        self._bytes += size
        if self.unique:
            self._keys.add(msg.identity)
        return True

    def drain(self) -> list[BusEvent]:
        """Every event kept, oldest first; the log is empty afterwards."""
        out = list(self)
        self._events.clear()
        self._keys.clear()
        self._bytes = 0
        return out

    @property
    def bytes(self) -> int:
        """Total :func:`event_bytes` kept."""
        return self._bytes

    def __len__(self) -> int:
        return len(self._events)

    def __iter__(self) -> Iterator[BusEvent]:
        return (msg for msg, _ in self._events)
