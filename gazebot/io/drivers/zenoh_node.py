"""What every gazebot node on the bus shares: a ROS 2 node on the rmw_zenoh wire
(:class:`~gazebot.io.drivers.rmw.node.RosNode`), the event topics (``robot/events``,
``handover/events``) and their history queryable,
health on ``/diagnostics``, and peer presence through the nodes' liveliness tokens.

Zenoh runs subscription callbacks on its own threads: they only decode and store; the node's
loop does the work. A callback never raises (a malformed message is counted, logged and
dropped by topic).

Peers are the other nodes in the same namespace: alive while their ``@ros2_lv`` node token
exists and their ``/diagnostics`` heartbeats (once seen) are not older than ``peer_timeout``.

The event history is the one thing ROS 2 has no topic for: each node answers Zenoh queries on
``@gazebot_history/<domain>/<namespace>/<node>`` with the events it has seen, one CDR
``gazebot_msgs/msg/HandoverEvent`` per reply, so a restarted engine catches up (resync).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar, TypeVar, cast

from gazebot.io.drivers.event_log import EventLog
from gazebot.io.drivers.rmw.attachment import Attachment, AttachmentError
from gazebot.io.drivers.rmw.graph import Entity
from gazebot.io.drivers.rmw.names import Names, mangle
from gazebot.io.drivers.rmw.node import DropCounter, Publisher, Received, RosNode, TypeMismatch
from gazebot.io.ros2 import convert, topics
from gazebot.io.ros2.convert import RosDiagnosticArray, RosHandoverEvent
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.values import BusEvent, Json, NodeStatus, NodeTracking

if TYPE_CHECKING:
    import zenoh

    from gazebot.io.drivers.session import BusConfig

log = logging.getLogger("gazebot.io.drivers")
_Node = TypeVar("_Node", bound="ZenohNode")
_V = TypeVar("_V")

HISTORY_SPACE = "@gazebot_history"
#: Bytes of events a node keeps in its history (and in its inbox) by default.
HISTORY_BYTES = 2 * 1024 * 1024


def checked(what: str, build: Callable[[], _V]) -> _V:
    """``build()``; a value out of range (:class:`ValueError`) becomes a :class:`MessageError`
    of message type ``what`` (counted and dropped by the subscription)."""
    try:
        return build()
    except ValueError as exc:
        raise MessageError(what, str(exc)) from None


class ZenohNode:
    """A named gazebot node on the bus of one robot.

    Args:
        session: An open Zenoh session (closed by :meth:`close` only if ``owns_session``: it may
            be shared). names: Namespace, remapping, domain id and frame names.
        node: This node's ROS name (``engine``, ``sim``, ...): its liveliness token, the
            ``source`` of its events and the name of its ``/diagnostics`` status.
        owns_session: Close ``session`` in :meth:`close` (set by :meth:`open`).
        history_len: Events kept for the history queryable and the inbox.
        history_bytes: Bytes of events kept in each (see :mod:`gazebot.io.drivers.event_log`;
            an event above the event topics' size cap is not kept).
        peer_timeout: A peer whose heartbeats stop for this long (s) counts as lost even if its
            session (and token) lingers.
        clock: Monotonic clock (s).
        max_bytes: Size cap of incoming messages by resolved topic (default 4 MiB).
    """

    #: The node name :meth:`open` uses when none is given.
    default_node: ClassVar[str] = "node"

    def __init__(
        self,
        session: zenoh.Session,
        names: Names,
        node: str,
        *,
        owns_session: bool = False,
        history_len: int = 1000,
        history_bytes: int = HISTORY_BYTES,
        peer_timeout: float = 2.0,
        clock: Callable[[], float] = time.monotonic,
        max_bytes: dict[str, int] | None = None,
    ) -> None:
        self.session = session
        self.names = names
        self.ros = RosNode(session, names, node, max_bytes=max_bytes)
        self.node = self.ros.name
        self._owns_session = owns_session
        self.peer_timeout = float(peer_timeout)
        self.clock = clock
        self.drops: DropCounter = self.ros.drops
        self.started = clock()
        self._lock = threading.Lock()
        self._closed = False
        event_cap = topics.max_bytes_of(topics.EVENTS.name)
        self._inbox = EventLog(history_len, history_bytes, event_cap)
        self._history = EventLog(history_len, history_bytes, event_cap, unique=True)
        self._last_beat: dict[str, float] = {}
        self._status_seq = 0
        self._event_seq = 0
        self._seen_nodes: set[str] = set()
        self.ros.on_graph = self._on_graph

        # Robot events (category ``robot``) on ``robot/events``, the others on
        # ``handover/events``; every node hears both.
        self._event_pubs = {
            name: self.ros.publisher(t.name, t.type)
            for name, t in (("robot", topics.ROBOT_EVENTS), ("other", topics.EVENTS))
        }
        self._status_pub = self.ros.publisher(topics.DIAGNOSTICS.name, topics.DIAGNOSTICS.type)
        for t in (topics.ROBOT_EVENTS, topics.EVENTS):
            self.ros.subscription(t.name, t.type, self._on_event)
        self.ros.subscription(topics.DIAGNOSTICS.name, topics.DIAGNOSTICS.type, self._on_status)
        self.ros.declare(session.declare_queryable(self._history_key(self.node), self._on_query))

    @classmethod
    def open(cls: type[_Node], config: BusConfig, node: str | None = None, **kwargs: Any) -> _Node:
        """Open a session for ``config`` and a node named ``node`` (default
        :attr:`default_node`) that closes the session with itself; ``kwargs`` go to the
        constructor. The session is closed again if the node cannot be built."""
        from gazebot.io.drivers.session import open_session

        session = open_session(config)
        try:
            return cls(session, config.names, node or cls.default_node, owns_session=True,
                       **kwargs)
        except Exception:
            session.close()
            raise

    def announce(self) -> None:
        """Declare the node's liveliness token: call last in a subclass' ``__init__``, so a
        peer that sees the node also finds all its subscriptions declared."""
        self.ros.announce()

    def _history_key(self, node: str) -> str:
        return f"{HISTORY_SPACE}/{self.names.domain_id}/{mangle(self.names.namespace)}/{node}"

    # -- plumbing --------------------------------------------------------------------------
    def _on_event(self, ros: RosHandoverEvent, rx: Received) -> None:
        seq = rx.attachment.sequence_number - 1 if rx.attachment is not None else 0
        msg = convert.event_of(ros, seq)
        with self._lock:
            self._remember(msg)
            if msg.source != self.node:
                self._inbox.append(msg)

    def _remember(self, msg: BusEvent) -> None:
        self._history.append(msg)

    def _on_graph(self, entity: Entity, alive: bool) -> None:
        if entity.kind == "NN" and alive and entity.namespace == self.names.namespace:
            with self._lock:  # a new life: wait for its first heartbeat
                self._last_beat.pop(entity.node, None)

    def _on_status(self, ros: RosDiagnosticArray, rx: Received) -> None:
        now = self.clock()
        with self._lock:
            for health in convert.health_of(ros):
                if health.node != self.node:
                    self._last_beat[health.node] = now

    def _on_query(self, query: zenoh.Query) -> None:
        with self._lock:
            events = list(self._history)
        try:
            for msg in events:
                pub = self._event_pub(msg)
                att = Attachment(msg.seq + 1, round(msg.stamp * 1e9), pub.gid)
                query.reply(self._history_key(self.node),
                            pub.codec.encode(convert.handover_event(msg)),
                            attachment=att.encode())
        except Exception:
            log.exception("could not answer the event history query")

    # -- events ----------------------------------------------------------------------------
    def _event_pub(self, msg: BusEvent) -> Publisher:
        return self._event_pubs["robot" if msg.category == "robot" else "other"]

    def next_event_seq(self) -> int:
        """The number of this node's next event (from 0)."""
        with self._lock:
            self._event_seq += 1
            return self._event_seq - 1

    def publish_event(self, event: BusEvent) -> None:
        """Publish one of this node's events (and keep it in the history)."""
        with self._lock:
            self._remember(event)
        if not self._closed:
            self._event_pub(event).publish(convert.handover_event(event))

    def history(self) -> list[BusEvent]:
        """The events this node has seen (its own and others'), in arrival order."""
        with self._lock:
            return list(self._history)

    def poll_events(self) -> list[BusEvent]:
        """Events other nodes published since the last call, oldest first."""
        with self._lock:
            return self._inbox.drain()

    def event_history(self, timeout: float = 1.0) -> list[BusEvent]:
        """Ask every other node for the events it has seen; merged, de-duplicated, sorted by
        time. Malformed replies are counted and skipped; no answer gives ``[]``. What is
        kept is bounded as the node's own history is (the replies received last are kept)."""
        selector = self._history_key("*")
        codec = self._event_pubs["other"].codec
        merged = EventLog(self._history.max_events, self._history.max_bytes,
                          self._history.max_event_bytes, unique=True)
        import zenoh

        # One reply per event from each node: no consolidation (by default Zenoh keeps only
        # the latest reply per key).
        replies = self.session.get(selector, timeout=timeout,
                                   consolidation=zenoh.ConsolidationMode.NONE)
        for reply in replies:
            if reply.ok is None:
                continue
            sample = reply.ok
            if str(sample.key_expr) == self._history_key(self.node):
                continue
            try:
                seq = 0
                if sample.attachment is not None:
                    seq = Attachment.decode(sample.attachment.to_bytes()).sequence_number - 1
                ros = cast(RosHandoverEvent, codec.decode(sample.payload.to_bytes()))
                msg = convert.event_of(ros, seq)
            except (MessageError, AttachmentError) as exc:
                self.drops.drop(selector, str(exc))
                continue
            merged.append(msg)
        return sorted(merged, key=lambda m: (m.t, m.detected_at, m.stamp))

    # -- status ----------------------------------------------------------------------------
    def peers(self) -> dict[str, bool]:
        """Other nodes of this namespace seen: alive when their node token exists and their
        heartbeats (once seen) are not older than ``peer_timeout``."""
        now = self.clock()
        alive_nodes = {e.node for e in self.ros.graph.nodes(self.names.namespace)}
        alive_nodes.discard(self.node)
        with self._lock:
            seen = set(self._seen_nodes) | alive_nodes
            self._seen_nodes = seen
            beats = dict(self._last_beat)
        out = {}
        for node in seen:
            beat = beats.get(node)
            out[node] = node in alive_nodes and (beat is None or now - beat <= self.peer_timeout)
        for node, beat in beats.items():
            out.setdefault(node, now - beat <= self.peer_timeout)
        return out

    def dropped(self) -> dict[str, int]:
        """Malformed messages dropped so far, by topic."""
        return self.drops.counts()

    def callback_faults(self) -> dict[str, int]:
        """Subscription callbacks that raised (the message is lost, the node goes on), by
        topic."""
        return self.ros.faults.counts()

    def callback_fault_reasons(self) -> dict[str, str]:
        """The last exception of each topic's failing callback, one line."""
        return self.ros.faults.reasons()

    def type_mismatches(self) -> dict[str, TypeMismatch]:
        """Topics on which a publisher of another type (or type version) was heard."""
        return self.drops.mismatches()

    def heartbeat(
        self,
        tracking: NodeTracking = "n/a",
        phase: str | None = None,
        info: dict[str, Json] | None = None,
        stopping: bool = False,
        degraded: bool = False,
    ) -> NodeStatus:
        """Publish and return this node's heartbeat; ``state`` is ``degraded`` when a peer is
        lost, tracking is not flowing or the caller says so."""
        peers = self.peers()
        degraded = degraded or not all(peers.values()) or tracking in ("hold", "lost")
        with self._lock:
            seq = self._status_seq
            self._status_seq += 1
        msg = NodeStatus(
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
        self.publish_status(msg)
        return msg

    def publish_status(self, status: NodeStatus) -> None:
        """Publish a heartbeat on ``/diagnostics`` (nothing once closed)."""
        if not self._closed:
            self._status_pub.publish(convert.diagnostics(status, status.stamp))

    # -- lifetime --------------------------------------------------------------------------
    @property
    def closed(self) -> bool:
        """Whether :meth:`close` was called."""
        return self._closed

    def close(self) -> None:
        """Undeclare everything this node declared (the node token first), then close the
        session if the node owns it; idempotent."""
        if self._closed:
            return
        self._closed = True
        self.ros.close()
        if self._owns_session:
            self.session.close()
