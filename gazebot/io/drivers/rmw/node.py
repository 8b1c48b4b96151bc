"""A ROS 2 node on a Zenoh session, speaking rmw_zenoh's wire: publishers put CDR messages with
rmw_zenoh's attachment on ``<domain>/<topic>/<DDS type>/<hash>``; subscriptions decode them;
every node, publisher and subscription holds its liveliness token under ``@ros2_lv``, and the
node keeps the graph the other tokens describe.

Transient local (latched) endpoints are rmw_zenoh's: a Zenoh ``AdvancedPublisher`` with a cache
of ``depth`` samples, publisher detection (a liveliness token ``<key>/@adv/pub/...``) and, when
reliable, a sporadic heartbeat for sample-miss detection; an ``AdvancedSubscriber`` that queries
the caches of the publishers already there and of late-joining ones for their last ``depth``
samples (and, when reliable, recovers a missed last sample on a heartbeat). Volatile endpoints are
plain Zenoh publishers and subscribers with rmw_zenoh's reliability and congestion control.

Subscriptions listen to their topic whatever the type (``<domain>/<topic>/*/*``) so that a
publisher of another type or another version of the type is reported, not silently unheard.
Zenoh runs callbacks on its own threads: a subscription callback never raises; anything
malformed is counted by topic (:class:`DropCounter`) and dropped, and so is a message whose
handler fails in any other way (one rate-limited log line, never a traceback per message).
"""

from __future__ import annotations

import itertools
import logging
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from gazebot.io.drivers.rmw.attachment import (
    Attachment,
    AttachmentError,
    LegacyAttachmentError,
    gid_of,
)
from gazebot.io.drivers.rmw.graph import ADMIN_SPACE, Entity, Graph, Kind
from gazebot.io.drivers.rmw.names import Names, check_namespace, check_node_name
from gazebot.io.drivers.rmw.qos import HEARTBEAT_S, KEEP_ALL, QosProfile, qos_of
from gazebot.io.ros2.codec import MAX_PAYLOAD_BYTES, Codec
from gazebot.io.ros2.errors import MessageError, one_line
from gazebot.io.ros2.names import ros_type_name
from gazebot.io.ros2.topics import durability_of, max_bytes_of

if TYPE_CHECKING:
    import zenoh
    from rosbags.typesys.store import Typestore

log = logging.getLogger("gazebot.io.drivers")

# Entity ids unique within the process, hence within every session (rmw_zenoh counts per context).
_entity_ids = itertools.count(1)


@dataclass(frozen=True)
class TypeMismatch:
    """A publisher on ``topic`` speaks another type (or another definition of it, by hash)."""

    topic: str
    expected: tuple[str, ...]
    received: str

    def __str__(self) -> str:
        return (f"type mismatch on {self.topic}: expected {' or '.join(self.expected)}, "
                f"received {self.received}")


class DropCounter:
    """Counts dropped messages by topic; logs the first ``log_first`` of each topic, then every
    ``log_every``-th, so a flood of garbage cannot flood the log. Keeps the last reason and the
    type mismatches seen."""

    def __init__(self, log_first: int = 3, log_every: int = 100, logs: bool = True) -> None:
        self.log_first = log_first
        self.log_every = log_every
        self.logs = logs
        self._counts: dict[str, int] = {}
        self._reasons: dict[str, str] = {}
        self._mismatches: dict[str, TypeMismatch] = {}
        self._lock = threading.Lock()

    def drop(self, topic: str, reason: str, mismatch: TypeMismatch | None = None) -> None:
        """Count one message dropped on ``topic`` for ``reason`` (and the type mismatch, if that
        was it); logs rate-limited."""
        reason = one_line(reason)
        with self._lock:
            n = self._counts[topic] = self._counts.get(topic, 0) + 1
            self._reasons[topic] = reason
            if mismatch is not None:
                self._mismatches[topic] = mismatch
        if self.logs and (n <= self.log_first or n % self.log_every == 0):
            log.warning("dropped message #%d on %s: %s", n, topic, reason)

    def counts(self) -> dict[str, int]:
        """Messages dropped so far, by topic."""
        with self._lock:
            return dict(self._counts)

    def reasons(self) -> dict[str, str]:
        """The last reason a message was dropped, by topic."""
        with self._lock:
            return dict(self._reasons)

    def mismatches(self) -> dict[str, TypeMismatch]:
        """The type mismatches seen, by topic."""
        with self._lock:
            return dict(self._mismatches)

    @property
    def total(self) -> int:
        """Messages dropped so far on all topics."""
        with self._lock:
            return sum(self._counts.values())


class Publisher:
    """One ROS publisher: a Zenoh publisher on the topic's key and its ``MP`` token."""

    def __init__(self, node: RosNode, topic: str, codec: Codec, qos: QosProfile) -> None:
        self.node = node
        self.topic = topic
        self.codec = codec
        self.key = node.names.key(topic, codec.info.dds_name, codec.info.hash)
        self.entity = node.entity("MP", topic, codec, qos)
        self.gid = gid_of(self.entity.token())
        self._seq = 0
        self._lock = threading.Lock()
        self._pub = _declare_publisher(node.session, self.key, qos)
        self._token = node.session.liveliness().declare_token(self.entity.token())

    def publish(self, msg: object) -> bool:
        """Serialize and put ``msg``; ``False`` once the node is closed.

        Raises:
            MessageError: ``msg`` is not a message of this publisher's type.
        """
        return self.publish_raw(self.codec.encode(msg))

    def publish_raw(self, data: bytes) -> bool:
        """Put CDR bytes as they are (with the attachment)."""
        if self.node.closed:
            return False
        with self._lock:
            self._seq += 1
            att = Attachment(self._seq, time.time_ns(), self.gid).encode()
        try:
            self._pub.put(data, attachment=att)
        except Exception:
            if self.node.closed:  # closed by another thread meanwhile
                return False
            raise
        return True

    def subscribed(self) -> bool:
        """Whether a subscription of this topic and type exists in the graph (rmw_zenoh's
        matched count comes from the same tokens)."""
        return any(e.type_hash == self.codec.info.hash
                   for e in self.node.graph.endpoints(self.topic, "MS"))

    def undeclare(self) -> None:
        """Undeclare the publisher's token and its Zenoh publisher (quiet if the session is
        closed)."""
        undeclare_quietly(self._token, self._pub)


@dataclass(frozen=True)
class Received:
    """What came with a message: its ``topic``, ROS ``type`` and the publisher's
    ``attachment`` (``None`` when it had none or an unreadable one)."""

    topic: str
    type: str
    attachment: Attachment | None


Handler = Callable[[Any, Received], None]


class Subscription:
    """One ROS subscription of one or more accepted types, with its ``MS`` token (of the first
    type: the one ``ros2 topic list -t`` shows)."""

    def __init__(self, node: RosNode, topic: str, codecs: Sequence[Codec], handler: Handler,
                 qos: QosProfile, raw: bool = False) -> None:
        self.node = node
        self.topic = topic
        self.handler = handler
        self.raw = raw
        self._by_dds = {c.info.dds_name: c for c in codecs}
        self._expected = tuple(f"{c.info.name} ({c.info.hash})" for c in codecs)
        self.entity = node.entity("MS", topic, codecs[0], qos)
        self.received = 0
        self._sub = _declare_subscriber(node.session, node.names.key_any_type(topic), self._on,
                                        qos)
        self._token = node.session.liveliness().declare_token(self.entity.token())

    def _on(self, sample: zenoh.Sample) -> None:
        drops = self.node.drops
        key = str(sample.key_expr)
        head, _, type_hash = key.rpartition("/")
        dds = head.rpartition("/")[2]
        codec = self._by_dds.get(dds)
        if codec is None or codec.info.hash != type_hash:
            try:
                name = ros_type_name(dds)
            except MessageError:
                name = dds
            mismatch = TypeMismatch(self.topic, self._expected, f"{name} ({type_hash})")
            drops.drop(self.topic, str(mismatch), mismatch)
            return
        size = len(sample.payload)
        if size > codec.max_bytes:  # dropped before its bytes are copied out of Zenoh's buffer
            drops.drop(self.topic, f"oversized: {size} bytes, at most {codec.max_bytes}")
            return
        data = sample.payload.to_bytes()
        try:
            msg = data if self.raw else codec.decode(data)
        except MessageError as exc:
            drops.drop(self.topic, exc.reason)
            return
        att = None
        if sample.attachment is not None:
            try:
                att = Attachment.decode(sample.attachment.to_bytes())
            except LegacyAttachmentError:
                self.node.legacy_peer_seen(self.topic)
            except AttachmentError:
                att = None
            if att is not None and att.legacy:
                self.node.legacy_peer_seen(self.topic)
        self.received += 1
        try:
            self.handler(msg, Received(self.topic, codec.info.name, att))
        except MessageError as exc:  # the handler found a value it cannot use (NaN, ...)
            drops.drop(self.topic, exc.reason)
        except Exception as exc:  # noqa: BLE001 - whatever a message causes, it is a drop
            # A crafted message must not kill Zenoh's thread nor flood the log with a
            # traceback per message: a drop of the topic (one rate-limited line, like malformed
            # CDR), and a callback fault the node reports (``faults``, quiet).
            reason = f"handler failed: {type(exc).__name__}: {exc}"
            drops.drop(self.topic, reason)
            self.node.faults.drop(self.topic, reason)

    def undeclare(self) -> None:
        """Undeclare the subscription's token and its Zenoh subscriber (quiet if the session is
        closed)."""
        undeclare_quietly(self._token, self._sub)


class RosNode:
    """A ROS 2 node named ``name`` in ``names.namespace`` on ``session``.

    Args:
        session: An open Zenoh session (not closed by :meth:`close`).
        names: Namespace, remapping and domain id.
        name: The node's name.
        store: The type system (default: gazebot's, :func:`gazebot.io.ros2.typestore.typestore`).
        max_bytes: Largest payload a subscription decodes, by resolved topic (default: the
            topic's cap in :mod:`gazebot.io.ros2.topics`, else
            :data:`~gazebot.io.ros2.codec.MAX_PAYLOAD_BYTES`).
        on_graph: Called with ``(entity, alive)`` for each token change (on Zenoh's thread).
    """

    def __init__(
        self,
        session: zenoh.Session,
        names: Names,
        name: str,
        *,
        store: Typestore | None = None,
        max_bytes: dict[str, int] | None = None,
        on_graph: Callable[[Entity, bool], None] | None = None,
    ) -> None:
        from gazebot.io.ros2.typestore import typestore

        self.session = session
        self.names = names
        self.name = check_node_name(name)
        check_namespace(names.namespace)
        self.store = store if store is not None else typestore()
        self.max_bytes = dict(max_bytes or {})
        self.zid = str(session.info.zid())
        self.node_id = next(_entity_ids)
        self.graph = Graph(names.domain_id)
        self.drops = DropCounter()
        # Handler failures (bugs or inputs a handler did not expect), by topic.
        self.faults = DropCounter(logs=False)  # each is in ``drops`` too, logged there
        self.closed = False
        self.on_graph = on_graph
        self._codecs: dict[tuple[str, int], Codec] = {}
        self._entities: list[Any] = []
        self._token: Any = None
        self._legacy_warned = False
        self._graph_sub = session.liveliness().declare_subscriber(
            f"{ADMIN_SPACE}/{names.domain_id}/**", self._on_token, history=True)

    # -- graph -----------------------------------------------------------------------------
    def entity(self, kind: Kind, topic: str | None = None, codec: Codec | None = None,
               qos: QosProfile | None = None) -> Entity:
        """A new entity of this node (a fresh id for endpoints)."""
        eid = self.node_id if kind == "NN" else next(_entity_ids)
        return Entity(
            self.names.domain_id, self.zid, self.node_id, eid, kind, self.names.namespace,
            self.name, topic=topic, dds_type=codec.info.dds_name if codec else None,
            type_hash=codec.info.hash if codec else None, qos=qos,
        )

    @property
    def node_entity(self) -> Entity:
        """The node's own graph entity (kind ``NN``)."""
        return self.entity("NN")

    def _on_token(self, sample: zenoh.Sample) -> None:
        import zenoh

        alive = sample.kind == zenoh.SampleKind.PUT
        entity = self.graph.update(str(sample.key_expr), alive)
        if entity is not None and self.on_graph is not None:
            try:
                self.on_graph(entity, alive)
            except Exception:
                log.exception("graph callback failed")

    def legacy_peer_seen(self, topic: str) -> None:
        """A sample with the labelled attachment of rmw_zenoh 0.2.0-0.2.3 arrived: warn once
        per node (its message is used all the same)."""
        if not self._legacy_warned:
            self._legacy_warned = True
            log.warning("a publisher on %s uses rmw_zenoh 0.2.0-0.2.3 (labelled attachment); "
                        "gazebot reads it, but supports rmw_zenoh 0.2.4 and later (docs/bus.md)",
                        topic)

    def announce(self) -> None:
        """Declare the node's own token: call after the node's endpoints, so a peer that sees
        the node also finds all its subscriptions declared."""
        if self._token is None and not self.closed:
            self._token = self.session.liveliness().declare_token(self.node_entity.token())

    # -- endpoints -------------------------------------------------------------------------
    def codec(self, ros_type: str, topic: str = "", name: str = "") -> Codec:
        """The codec of ``ros_type`` with the size cap of ``topic`` (resolved; ``name``: as
        the topic table names it)."""
        cap = self.max_bytes.get(topic, max_bytes_of(name) if name else MAX_PAYLOAD_BYTES)
        key = (ros_type, cap)
        if key not in self._codecs:
            self._codecs[key] = Codec.for_type(self.store, ros_type, cap)
        return self._codecs[key]

    def publisher(self, name: str, ros_type: str, qos: QosProfile | None = None) -> Publisher:
        """A publisher of ``ros_type`` on topic ``name`` (resolved: namespace, remapping);
        ``qos`` defaults to the topic's durability and depth in :mod:`gazebot.io.ros2.topics`
        (ROS 2's default profile for a topic not in it)."""
        topic = self.names.resolve(name)
        pub = Publisher(self, topic, self.codec(ros_type, topic, name), qos or qos_of(
            *durability_of(name)))
        self._entities.append(pub)
        return pub

    def subscription(self, name: str, ros_types: str | Sequence[str], handler: Handler,
                     qos: QosProfile | None = None, raw: bool = False) -> Subscription:
        """Subscribe to topic ``name`` accepting ``ros_types`` (the first one is advertised);
        ``handler(msg, received)`` runs on Zenoh's thread for each well-formed message (``raw``:
        with the CDR bytes as received instead of the message). ``qos`` defaults as for
        :meth:`publisher`; a transient-local one also receives the last ``depth`` messages of
        each transient-local publisher, whenever it started."""
        topic = self.names.resolve(name)
        types = [ros_types] if isinstance(ros_types, str) else list(ros_types)
        sub = Subscription(self, topic, [self.codec(t, topic, name) for t in types], handler,
                           qos or qos_of(*durability_of(name)), raw)
        self._entities.append(sub)
        return sub

    def declare(self, entity: Any) -> Any:
        """Keep a further Zenoh entity (queryable, ...) to undeclare in :meth:`close`."""
        self._entities.append(entity)
        return entity

    # -- lifetime --------------------------------------------------------------------------
    def close(self) -> None:
        """Undeclare the node's token, then its endpoints and the graph subscriber;
        idempotent."""
        if self.closed:
            return
        self.closed = True
        undeclare_quietly(self._token, *reversed(self._entities), self._graph_sub)
        self._entities.clear()


def undeclare_quietly(*entities: Any) -> None:
    """Undeclare each Zenoh entity in order, skipping ``None``; one that fails (its session
    already closed) does not stop the rest."""
    for entity in entities:
        if entity is None:
            continue
        try:
            entity.undeclare()
        except Exception:  # the session may already be closed: nothing left to undeclare
            pass


def _declare_publisher(session: zenoh.Session, key: str, qos: QosProfile) -> Any:
    """The Zenoh publisher of an rmw_zenoh publisher of ``qos`` (``PublisherData::make``):
    reliability as asked, congestion control ``BLOCK`` only for reliable keep-all; for transient
    local an ``AdvancedPublisher`` with a cache of ``depth`` samples and publisher detection, and
    sample-miss detection by sporadic heartbeat when reliable."""
    import zenoh
    import zenoh.ext as zext

    reliability = zenoh.Reliability.RELIABLE if qos.reliable else zenoh.Reliability.BEST_EFFORT
    congestion = (zenoh.CongestionControl.BLOCK if qos.reliable and qos.history == KEEP_ALL
                  else zenoh.CongestionControl.DROP)
    if not qos.transient_local:
        return session.declare_publisher(key, reliability=reliability,
                                         congestion_control=congestion)
    miss = (zext.MissDetectionConfig(heartbeat=None, sporadic_heartbeat=HEARTBEAT_S)
            if qos.reliable else None)
    try:
        return zext.declare_advanced_publisher(
            session, key, reliability=reliability, congestion_control=congestion,
            cache=zext.CacheConfig(max_samples=qos.depth), publisher_detection=True,
            sample_miss_detection=miss)
    except zenoh.ZError as exc:
        # A best-effort cache orders by timestamp: the session needs Zenoh's ``timestamping``.
        raise ValueError(f"cannot publish {key} transient local: {exc}") from exc


def _declare_subscriber(session: zenoh.Session, key: str, callback: Callable[[zenoh.Sample], None],
                        qos: QosProfile) -> Any:
    """The Zenoh subscriber of an rmw_zenoh subscription of ``qos``
    (``SubscriptionData::init``): plain when volatile; for transient local an
    ``AdvancedSubscriber`` with subscriber detection and a history query of ``depth`` samples
    per publisher that also detects late-joining publishers, and, when reliable, last-sample
    recovery on the publishers' heartbeats."""
    if not qos.transient_local:
        return session.declare_subscriber(key, callback)
    import zenoh.ext as zext

    recovery = zext.RecoveryConfig(periodic_queries=None, heartbeat=True) if qos.reliable else None
    return zext.declare_advanced_subscriber(
        session, key, callback, subscriber_detection=True, recovery=recovery,
        history=zext.HistoryConfig(detect_late_publishers=True, max_samples=qos.depth))
