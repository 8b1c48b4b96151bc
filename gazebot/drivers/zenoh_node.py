"""What every gazebot node on the bus shares: strict decoding with drop counting, the events topic
and its history queryable, heartbeats, and peer presence through liveliness tokens.

Zenoh runs subscriber callbacks on its own threads: they only decode and store; the node's loop
does the work. A callback never raises (a malformed payload is counted, logged and dropped).
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar, Literal, TypeVar

from gazebot.drivers.keys import KeyLayout, check_chunk
from gazebot.drivers.payloads import (
    EventHistoryMsg,
    EventMsg,
    Msg,
    PayloadError,
    StatusMsg,
)

if TYPE_CHECKING:
    import zenoh

    from gazebot.drivers.session import BusConfig

log = logging.getLogger("gazebot.drivers")
_Node = TypeVar("_Node", bound="ZenohNode")


class DropCounter:
    """Counts dropped payloads by key; logs the first ``log_first`` of each key, then every
    ``log_every``-th, so a flood of garbage cannot flood the log."""

    def __init__(self, log_first: int = 3, log_every: int = 100) -> None:
        self.log_first = log_first
        self.log_every = log_every
        self._counts: dict[str, int] = {}
        self._versions: dict[str, Any] = {}
        self._lock = threading.Lock()

    def drop(self, key: str, reason: str, version: Any = None) -> None:
        """Count a dropped payload on ``key``; ``version``: the protocol version it spoke when
        that was the reason."""
        with self._lock:
            n = self._counts.get(key, 0) + 1
            self._counts[key] = n
            if version is not None:
                self._versions[key] = version
        if n <= self.log_first or n % self.log_every == 0:
            log.warning("dropped payload #%d on %s: %s", n, key, reason)

    def counts(self) -> dict[str, int]:
        with self._lock:
            return dict(self._counts)

    def versions(self) -> dict[str, Any]:
        """The other protocol version last seen on each key that had one."""
        with self._lock:
            return dict(self._versions)

    @property
    def total(self) -> int:
        with self._lock:
            return sum(self._counts.values())


def _event_key(msg: EventMsg) -> tuple[str, int, float]:
    # seq restarts with a node, stamp tells the two lives apart.
    return (msg.source, msg.seq, msg.stamp)


class ZenohNode:
    """A named node on the bus of one robot.

    Args:
        session: An open Zenoh session (closed by :meth:`close` only if ``owns_session``: it may
            be shared).
        keys: The robot's key layout.
        node: This node's name (``engine``, ``sim``, ...): its liveliness token, the ``source``
            of its events and the ``node`` of its heartbeats.
        owns_session: Close ``session`` in :meth:`close` (set by :meth:`open`).
        history_len: Events kept for the history queryable and the inbox.
        peer_timeout: A peer whose heartbeats stop for this long (s) counts as lost even if its
            session (and token) lingers.
        clock: Monotonic clock (s).
    """

    #: The node name :meth:`open` uses when none is given.
    default_node: ClassVar[str] = "node"

    def __init__(
        self,
        session: zenoh.Session,
        keys: KeyLayout,
        node: str,
        *,
        owns_session: bool = False,
        history_len: int = 1000,
        peer_timeout: float = 2.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.session = session
        self.keys = keys
        self.node = check_chunk(node, "node name")
        self._owns_session = owns_session
        self.peer_timeout = float(peer_timeout)
        self.clock = clock
        self.drops = DropCounter()
        self.started = clock()
        self._lock = threading.Lock()
        self._closed = False
        self._entities: list[Any] = []
        self._inbox: deque[EventMsg] = deque(maxlen=history_len)
        self._history: deque[EventMsg] = deque(maxlen=history_len)
        self._history_keys: set[tuple[str, int, float]] = set()
        self._alive: dict[str, bool] = {}
        self._last_beat: dict[str, float] = {}
        self._event_seq = 0
        self._status_seq = 0

        self._event_pub = self._declare(session.declare_publisher(keys.events))
        self._status_pub = self._declare(session.declare_publisher(keys.status))
        self.subscribe(keys.events, EventMsg, self._on_event)
        self.subscribe(keys.status, StatusMsg, self._on_status)
        liveliness = session.liveliness()
        self._declare(liveliness.declare_subscriber(keys.alive_all, self._on_alive, history=True))
        self._declare(session.declare_queryable(keys.events_history(self.node), self._on_query))
        self._token: Any = None

    @classmethod
    def open(cls: type[_Node], config: BusConfig, node: str | None = None, **kwargs: Any) -> _Node:
        """Open a session for ``config`` and a node named ``node`` (default
        :attr:`default_node`) that closes the session with itself; ``kwargs`` go to the
        constructor. The session is closed again if the node cannot be built."""
        from gazebot.drivers.session import open_session

        session = open_session(config)
        try:
            return cls(session, config.keys, node or cls.default_node, owns_session=True, **kwargs)
        except Exception:
            session.close()
            raise

    def announce(self) -> None:
        """Declare the node's liveliness token: call last in a subclass' ``__init__``, so a
        peer that sees the node also finds all its subscribers declared."""
        if self._token is None:
            self._token = self._declare(
                self.session.liveliness().declare_token(self.keys.alive(self.node))
            )

    # -- plumbing --------------------------------------------------------------------------
    def put(self, publisher: Any, msg: Msg) -> bool:
        """Publish ``msg``; after :meth:`close` this is a no-op returning ``False``."""
        if self._closed:
            return False
        try:
            publisher.put(msg.encode())
        except Exception:
            if self._closed:  # closed by another thread meanwhile
                return False
            raise
        return True

    def _declare(self, entity: Any) -> Any:
        self._entities.append(entity)
        return entity

    def subscribe(self, key: str, model: type[Msg], handler: Callable[[Any], None]) -> None:
        """Subscribe to ``key``: each payload is decoded as ``model`` and handed to ``handler``;
        malformed ones are counted and dropped, handler errors logged."""

        def callback(sample: zenoh.Sample) -> None:
            try:
                msg = model.decode(sample.payload.to_bytes())
            except PayloadError as exc:
                self.drops.drop(key, exc.reason, getattr(exc, "version", None))
                return
            try:
                handler(msg)
            except Exception:  # a bug in a handler must not kill Zenoh's thread
                log.exception("handler for %s failed", key)

        self._declare(self.session.declare_subscriber(key, callback))

    def _on_event(self, msg: EventMsg) -> None:
        with self._lock:
            self._remember(msg)
            if msg.source != self.node:
                self._inbox.append(msg)

    def _remember(self, msg: EventMsg) -> None:
        key = _event_key(msg)
        if key in self._history_keys:
            return
        if len(self._history) == self._history.maxlen:
            self._history_keys.discard(_event_key(self._history[0]))
        self._history.append(msg)
        self._history_keys.add(key)

    def _on_status(self, msg: StatusMsg) -> None:
        if msg.node != self.node:
            with self._lock:
                self._last_beat[msg.node] = self.clock()

    def _on_alive(self, sample: zenoh.Sample) -> None:
        import zenoh

        node = self.keys.node_of_alive(str(sample.key_expr))
        if node is None or node == self.node:
            return
        with self._lock:
            self._alive[node] = sample.kind == zenoh.SampleKind.PUT
            if self._alive[node]:
                self._last_beat.pop(node, None)  # a new life: wait for its first heartbeat

    def _on_query(self, query: zenoh.Query) -> None:
        with self._lock:
            events = list(self._history)
        reply = EventHistoryMsg(node=self.node, events=events)
        try:
            query.reply(self.keys.events_history(self.node), reply.encode())
        except Exception:
            log.exception("could not answer the event history query")

    # -- events ----------------------------------------------------------------------------
    def next_event_seq(self) -> int:
        with self._lock:
            self._event_seq += 1
            return self._event_seq - 1

    def publish_event(self, msg: EventMsg) -> None:
        """Publish one of this node's events (and keep it in the history)."""
        with self._lock:
            self._remember(msg)
        self.put(self._event_pub, msg)

    def history(self) -> list[EventMsg]:
        """The events this node has seen (its own and others'), in arrival order."""
        with self._lock:
            return list(self._history)

    def poll_events(self) -> list[EventMsg]:
        """Events other nodes published since the last call, oldest first."""
        with self._lock:
            out = list(self._inbox)
            self._inbox.clear()
        return out

    def event_history(self, timeout: float = 1.0) -> list[EventMsg]:
        """Ask every other node for the events it has seen; merged, de-duplicated, sorted by
        time. Malformed replies are counted and skipped; no answer gives ``[]``."""
        key = self.keys.events_history_all
        merged: dict[tuple[str, int, float], EventMsg] = {}
        for reply in self.session.get(key, timeout=timeout):
            if reply.ok is None:
                continue
            try:
                hist = EventHistoryMsg.decode(reply.ok.payload.to_bytes())
            except PayloadError as exc:
                self.drops.drop(key, exc.reason)
                continue
            if hist.node == self.node:
                continue
            for msg in hist.events:
                merged.setdefault(_event_key(msg), msg)
        return sorted(merged.values(), key=lambda m: (m.t, m.detected_at, m.stamp))

    # -- status ----------------------------------------------------------------------------
    def peers(self) -> dict[str, bool]:
        """Other nodes seen: alive when their liveliness token exists and their heartbeats
        (once seen) are not older than ``peer_timeout``."""
        now = self.clock()
        with self._lock:
            out = {}
            for node, alive in self._alive.items():
                beat = self._last_beat.get(node)
                out[node] = alive and (beat is None or now - beat <= self.peer_timeout)
            for node, beat in self._last_beat.items():
                out.setdefault(node, now - beat <= self.peer_timeout)
        return out

    def dropped(self) -> dict[str, int]:
        return self.drops.counts()

    def foreign_versions(self) -> dict[str, Any]:
        """Keys on which payloads of another protocol version arrived, with that version."""
        return self.drops.versions()

    def heartbeat(
        self,
        tracking: Literal["ok", "waiting", "hold", "lost", "n/a"] = "n/a",
        phase: str | None = None,
        info: dict[str, Any] | None = None,
        stopping: bool = False,
    ) -> StatusMsg:
        """Publish and return this node's heartbeat; ``state`` is ``degraded`` when a peer is
        lost or tracking is not flowing."""
        peers = self.peers()
        degraded = not all(peers.values()) or tracking in ("hold", "lost")
        with self._lock:
            seq = self._status_seq
            self._status_seq += 1
        msg = StatusMsg(
            node=self.node,
            seq=seq,
            stamp=time.time(),
            uptime=max(0.0, self.clock() - self.started),
            state="stopping" if stopping else ("degraded" if degraded else "ok"),
            tracking=tracking,
            peers=peers,
            dropped=self.drops.counts(),
            phase=phase,
            info=info or {},
        )
        self.put(self._status_pub, msg)
        return msg

    def publish_status(self, msg: StatusMsg) -> None:
        self.put(self._status_pub, msg)

    # -- lifetime --------------------------------------------------------------------------
    @property
    def closed(self) -> bool:
        return self._closed

    def close(self) -> None:
        """Undeclare everything this node declared (the token last-first), then close the
        session if the node owns it; idempotent."""
        if self._closed:
            return
        self._closed = True
        for entity in reversed(self._entities):
            try:
                entity.undeclare()
            except Exception:  # the session may already be closed
                pass
        self._entities.clear()
        if self._owns_session:
            self.session.close()
