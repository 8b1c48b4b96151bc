"""Liveliness tokens of the ROS graph (``@ros2_lv/...``) and the graph they describe.

Every node, publisher and subscription declares one token while it exists; a node learns the
graph from the tokens it sees appear and vanish (rmw_zenoh's graph cache). A token's key:
``@ros2_lv/<domain>/<zid>/<node id>/<entity id>/<kind>/<enclave>/<namespace>/<node>`` and, for
publishers (``MP``) and subscriptions (``MS``), ``/<topic>/<DDS type>/<type hash>/<qos>``;
names are mangled (``/`` -> ``%``), the default enclave and the root namespace are ``%``.
Trailing chunks a newer rmw_zenoh adds after these are ignored.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, replace
from typing import Literal, cast

from gazebot.io.drivers.rmw.names import demangle, mangle
from gazebot.io.drivers.rmw.qos import QosProfile
from gazebot.io.ros2.names import ros_type_name

ADMIN_SPACE = "@ros2_lv"
Kind = Literal["NN", "MP", "MS", "SS", "SC"]
_KINDS = ("NN", "MP", "MS", "SS", "SC")
#: Chunks of an endpoint token as gazebot reads it. Newer rmw_zenoh releases append chunks
#: (14 in all): those after the QoS are not gazebot's concern and are ignored, as are any a
#: node token carries after its name.
ENDPOINT_CHUNKS = 13


@dataclass(frozen=True)
class Entity:
    """One graph entity as its token describes it.

    Attributes:
        domain_id: ROS domain.
        zid: Zenoh session id (hex) of the entity's process.
        node_id: Id of its node within the session.
        entity_id: Its own id within the session (a node's equals its ``node_id``).
        kind: ``NN`` node, ``MP`` publisher, ``MS`` subscription, ``SS``/``SC`` services.
        namespace: The node's namespace (``/gazebot``).
        node: The node's name.
        enclave: SROS enclave (``/`` by default).
        topic: Fully qualified topic name (endpoints only).
        dds_type: DDS type name (``geometry_msgs::msg::dds_::PointStamped_``).
        type_hash: ``RIHS01_...``.
        qos: The endpoint's QoS.
    """

    domain_id: int
    zid: str
    node_id: int
    entity_id: int
    kind: Kind
    namespace: str
    node: str
    enclave: str = "/"
    topic: str | None = None
    dds_type: str | None = None
    type_hash: str | None = None
    qos: QosProfile | None = None

    @property
    def ros_type(self) -> str | None:
        """``pkg/msg/Name`` of :attr:`dds_type`."""
        if not self.dds_type:
            return None
        try:
            return ros_type_name(self.dds_type)
        except ValueError:
            return None

    @property
    def node_fqn(self) -> str:
        """The node's fully qualified name, ``<namespace>/<node>``."""
        return f"{self.namespace.rstrip('/')}/{self.node}"

    def token(self) -> str:
        """The liveliness token's key expression."""
        key = (f"{ADMIN_SPACE}/{self.domain_id}/{self.zid}/{self.node_id}/{self.entity_id}/"
               f"{self.kind}/{mangle(self.enclave)}/{mangle(self.namespace)}/{mangle(self.node)}")
        if self.kind == "NN":
            return key
        if self.topic is None or self.dds_type is None or self.type_hash is None:
            raise ValueError(f"a {self.kind} token needs a topic, a type and a type hash")
        qos = (self.qos or QosProfile()).encode()
        return f"{key}/{mangle(self.topic)}/{self.dds_type}/{self.type_hash}/{qos}"

    @classmethod
    def parse(cls, key: str) -> Entity:
        """The entity of a token key; ``ValueError`` saying what is wrong."""
        parts = key.split("/")
        if len(parts) < 9 or parts[0] != ADMIN_SPACE:
            raise ValueError(f"not a ROS graph token: {key!r}")
        kind = parts[5]
        if kind not in _KINDS:
            raise ValueError(f"unknown entity kind {kind!r} in {key!r}")
        try:
            domain, node_id, entity_id = int(parts[1]), int(parts[3]), int(parts[4])
        except ValueError:
            raise ValueError(f"non-numeric domain or id in {key!r}") from None
        common = cls(domain_id=domain, zid=parts[2], node_id=node_id, entity_id=entity_id,
                     kind=cast(Kind, kind), enclave=demangle(parts[6]),
                     namespace=demangle(parts[7]), node=demangle(parts[8]))
        if kind == "NN":
            return common
        if len(parts) < ENDPOINT_CHUNKS:
            raise ValueError(
                f"{kind} token needs {ENDPOINT_CHUNKS} chunks, got {len(parts)}: {key!r}")
        return replace(common, topic=demangle(parts[9]), dds_type=parts[10],
                       type_hash=parts[11], qos=QosProfile.decode(parts[12]))


class Graph:
    """The entities currently alive, fed by a liveliness subscriber (thread-safe)."""

    def __init__(self, domain_id: int) -> None:
        self.domain_id = domain_id
        self._lock = threading.Lock()
        self._entities: dict[str, Entity] = {}
        self.bad_tokens = 0

    def update(self, key: str, alive: bool) -> Entity | None:
        """Apply one token appearing (``alive``) or vanishing; returns its entity, ``None`` for
        a token that is not a well-formed graph token of this domain (counted)."""
        try:
            entity = Entity.parse(key)
        except ValueError:
            with self._lock:
                self.bad_tokens += 1
            return None
        if entity.domain_id != self.domain_id:
            return None
        with self._lock:
            if alive:
                self._entities[key] = entity
            else:
                self._entities.pop(key, None)
        return entity

    def entities(self) -> list[Entity]:
        """Every entity alive in the graph."""
        with self._lock:
            return list(self._entities.values())

    def nodes(self, namespace: str | None = None) -> list[Entity]:
        """Nodes alive (in ``namespace`` if given)."""
        return [e for e in self.entities() if e.kind == "NN"
                and (namespace is None or e.namespace == namespace)]

    def endpoints(self, topic: str, kind: Kind) -> list[Entity]:
        """Publishers (``MP``) or subscriptions (``MS``) of ``topic``."""
        return [e for e in self.entities() if e.kind == kind and e.topic == topic]

    def topics(self) -> dict[str, set[tuple[str, str]]]:
        """Every topic with a publisher or subscription -> its ``(ROS type, hash)`` pairs."""
        out: dict[str, set[tuple[str, str]]] = {}
        for e in self.entities():
            if e.kind in ("MP", "MS") and e.topic is not None:
                out.setdefault(e.topic, set()).add((e.ros_type or str(e.dds_type),
                                                     str(e.type_hash)))
        return out
