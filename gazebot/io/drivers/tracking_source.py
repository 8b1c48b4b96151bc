"""One tracking source at a time: the first node whose samples arrive owns the tracking until it
goes silent; samples of any other source (a second tracker, with its own clock) are ignored and
reported, so its stamps never reach the sample assembly (where a clock going back means a
restart).

Sources are told apart by the publisher GID in each sample's attachment, resolved to the
publishing node (name and Zenoh session) through the ROS graph, so the hands and the face of one
tracker are one source. A sample that cannot be resolved so (no attachment, a GID that no live
publisher of the topic announced, or a GID whose sequence numbers go back: a second stream
copying it) never owns a part: it is refused (:meth:`SourceArbiter.refuse`) and reported as a
rival like a second tracker (issue 30: such samples were taken for the simulator's own).
Each part (``giver_hand``, ``receiver_hand``, ``giver_face``,
``gripper``, ``load_share``, from their topics or ``/tf``) is arbitrated on its own: a
motion-capture node may publish the hands while a separate face tracker publishes the face and a
robot bridge the gripper and the load share; only a second publisher of the same part is a rival.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass


def group_of(part: str) -> str:
    """The unit a part is arbitrated in: the part itself (each part has its own owner)."""
    return part


@dataclass
class _Owner:
    source: str
    last_seen: float


@dataclass(frozen=True)
class Rival:
    """A source whose samples were ignored: ``source``, the ``owner`` it competed with, the
    ``parts`` it was refused (``group``: the same, comma-joined, for messages) and how many of
    its samples were ignored (``ignored``)."""

    source: str
    group: str
    owner: str
    ignored: int
    parts: tuple[str, ...] = ()


class SourceArbiter:
    """Decides, per part, which source's samples are used (thread-safe).

    Args:
        timeout: An owner silent this long (s) loses the part to the next source heard.
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
        self._reported: set[tuple[str, str]] = set()  # (source, owner)

    def admit(self, part: str, source: str) -> str | None:
        """``None`` when ``source``'s sample of ``part`` is to be used, else the owner whose
        source keeps the part (the sample is to be dropped)."""
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

    def refuse(self, part: str, source: str) -> str:
        """Record a sample of ``part`` from ``source`` that is never to be used (an
        unidentified publisher): a rival of the part's owner (or of ``"the announced
        publishers"`` while none owns it). Returns that owner."""
        group = group_of(part)
        now = self.clock()
        with self._lock:
            owner = self._owners.get(group)
            name = (owner.source if owner is not None and now - owner.last_seen <= self.timeout
                    else "the announced publishers")
            _, n, _ = self._rivals.get((group, source), (name, 0, now))
            self._rivals[(group, source)] = (name, n + 1, now)
            return name

    def owners(self) -> dict[str, str]:
        """Part -> the source that owns it now (silent owners left out)."""
        now = self.clock()
        with self._lock:
            return {g: o.source for g, o in self._owners.items()
                    if now - o.last_seen <= self.timeout}

    def rivals(self) -> list[Rival]:
        """Sources ignored within the last ``timeout`` s, one per (source, owner) with every
        part it was refused."""
        now = self.clock()
        merged: dict[tuple[str, str], tuple[list[str], int]] = {}
        with self._lock:
            for (part, src), (owner, n, seen) in sorted(self._rivals.items()):
                if now - seen <= self.timeout:
                    parts, total = merged.get((src, owner), ([], 0))
                    merged[(src, owner)] = ([*parts, part], total + n)
        return [Rival(src, ", ".join(parts), owner, n, tuple(parts))
                for (src, owner), (parts, n) in sorted(merged.items())]

    def new_rivals(self) -> list[Rival]:
        """Rivals not returned by this method before (each reported once per owner while it
        competes; again if it comes back after going silent)."""
        current = self.rivals()
        with self._lock:
            keys = {(r.source, r.owner) for r in current}
            new = [r for r in current if (r.source, r.owner) not in self._reported]
            self._reported = (self._reported & keys) | {(r.source, r.owner) for r in new}
        return new
