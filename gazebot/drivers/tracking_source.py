"""One tracking source at a time: the first node whose samples arrive owns the tracking until it
goes silent; samples of any other source (a second tracker, with its own clock) are ignored and
reported, so its stamps never reach the sample assembly (where a clock going back means a
restart).

Sources are told apart by the publisher GID in each sample's attachment, resolved to the
publishing node (name and Zenoh session) through the ROS graph, so the hands and the face of one
tracker are one source. An implementation whose GIDs are not rmw_zenoh's hash of the token
(e.g. random ones) is identified by the topic's only publisher; failing that, its samples count
as one unidentified source. Parts are arbitrated in groups: the tracked points (hands, face,
from their topics or ``/tf``) are one group, the gripper and the load share one each, since a
robot bridge may publish those while a motion-capture node publishes the points.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

#: The group each tracking part is arbitrated in.
POINTS = "points"


def group_of(part: str) -> str:
    """``points`` for the tracked bodies, the part's own name for robot evidence."""
    return part if part in ("gripper", "load_share") else POINTS


@dataclass
class _Owner:
    source: str
    last_seen: float


@dataclass(frozen=True)
class Rival:
    """A source whose samples were ignored: ``source``, the ``group`` it published in, the
    ``owner`` it competed with, and how many samples were ignored (``ignored``)."""

    source: str
    group: str
    owner: str
    ignored: int


class SourceArbiter:
    """Decides, per group, which source's samples are used (thread-safe).

    Args:
        timeout: An owner silent this long (s) loses the group to the next source heard.
        clock: Monotonic clock (s).
    """

    def __init__(self, timeout: float = 1.0, clock: Callable[[], float] = time.monotonic) -> None:
        if not timeout > 0:
            raise ValueError(f"source timeout must be > 0 s, got {timeout!r}")
        self.timeout = timeout
        self.clock = clock
        self._lock = threading.Lock()
        self._owners: dict[str, _Owner] = {}
        self._rivals: dict[tuple[str, str], tuple[str, int, float]] = {}
        self._reported: set[tuple[str, str]] = set()

    def admit(self, part: str, source: str) -> str | None:
        """``None`` when ``source``'s sample of ``part`` is to be used, else the owner whose
        source keeps the group (the sample is to be dropped)."""
        group = group_of(part)
        now = self.clock()
        with self._lock:
            owner = self._owners.get(group)
            if owner is None or owner.source == source or now - owner.last_seen > self.timeout:
                self._owners[group] = _Owner(source, now)
                return None
            _, n, _ = self._rivals.get((group, source), (owner.source, 0, now))
            self._rivals[(group, source)] = (owner.source, n + 1, now)
            return owner.source

    def owners(self) -> dict[str, str]:
        """Group -> the source that owns it now (silent owners left out)."""
        now = self.clock()
        with self._lock:
            return {g: o.source for g, o in self._owners.items()
                    if now - o.last_seen <= self.timeout}

    def rivals(self) -> list[Rival]:
        """Sources ignored within the last ``timeout`` s."""
        now = self.clock()
        with self._lock:
            return [Rival(src, g, owner, n) for (g, src), (owner, n, seen) in
                    sorted(self._rivals.items()) if now - seen <= self.timeout]

    def new_rivals(self) -> list[Rival]:
        """Rivals not returned by this method before (each reported once per group while it
        competes; again if it comes back after going silent)."""
        current = self.rivals()
        with self._lock:
            keys = {(r.group, r.source) for r in current}
            new = [r for r in current if (r.group, r.source) not in self._reported]
            self._reported = (self._reported & keys) | {(r.group, r.source) for r in new}
        return new
