"""Inspecting a ROS 2 bus on Zenoh as ``ros2 topic`` / ``ros2 node`` do: the graph from the
liveliness tokens, subscriptions by the type a publisher advertises, and the statistics of a
topic's rate.

Works against any rmw_zenoh node, gazebot's among them: the tokens and key expressions are the
same (:mod:`.graph`, :mod:`.node`). The :class:`Inspector` is a :class:`~.node.RosNode` that
declares nothing until it subscribes, so listing the graph leaves no trace in it.
"""

from __future__ import annotations

import logging
import math
import os
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, fields, is_dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gazebot.io.drivers.rmw.graph import ADMIN_SPACE, Entity, Graph
from gazebot.io.drivers.rmw.names import Names
from gazebot.io.drivers.rmw.node import DropCounter, Handler, RosNode, Subscription

if TYPE_CHECKING:
    import zenoh

log = logging.getLogger("gazebot.io.drivers")

#: How long the graph must stay unchanged before a listing is taken as complete (s): the tokens
#: of one peer arrive together, those of peers found by gossip a little later.
QUIET_S = 0.5


def inspector_name() -> str:
    """The inspecting node's name: hidden (leading ``_``, as ``ros2`` CLI nodes are) and
    unique per process."""
    return f"_gazebot_cli_{os.getpid()}"


@dataclass(frozen=True)
class TopicSummary:
    """One topic of the graph.

    Attributes:
        name: Fully qualified topic name.
        types: ROS types advertised by its endpoints (more than one: a type conflict).
        publishers: Its publishers' entities.
        subscribers: Its subscriptions' entities.
    """

    name: str
    types: tuple[str, ...]
    publishers: tuple[Entity, ...]
    subscribers: tuple[Entity, ...]


def topic_summaries(graph: Graph) -> list[TopicSummary]:
    """Every topic with a publisher or a subscription, by name."""
    out = []
    for name, types in sorted(graph.topics().items()):
        out.append(TopicSummary(
            name, tuple(sorted({t for t, _ in types})),
            tuple(sorted(graph.endpoints(name, "MP"), key=lambda e: e.node_fqn)),
            tuple(sorted(graph.endpoints(name, "MS"), key=lambda e: e.node_fqn))))
    return out


class Inspector:
    """Watches the ROS graph of ``names.domain_id`` on ``session`` and subscribes to topics by
    their publishers' advertised types.

    Args:
        session: An open Zenoh session (not closed by :meth:`close`).
        names: Namespace (relative topic names resolve in it), remapping and domain id.
        name: The node's name, declared (in the root namespace) only once it subscribes
            (default :func:`inspector_name`).
    """

    def __init__(self, session: zenoh.Session, names: Names, name: str | None = None) -> None:
        self.session = session
        self.names = names
        self._changed = threading.Condition()
        self._last_change = time.monotonic()
        # The node itself lives in the root namespace, as ros2's command-line nodes do: a node
        # in a robot's namespace would count as that robot's peer, and as lost once it exits.
        self.node = RosNode(session, Names("/", domain_id=names.domain_id),
                            name or inspector_name(), on_graph=self._on_graph)
        # Counted, not logged: the caller reports them (a command line, in one line).
        self.node.drops = DropCounter(logs=False)

    @property
    def graph(self) -> Graph:
        """The ROS graph as the inspector's node sees it."""
        return self.node.graph

    @property
    def drops(self) -> DropCounter:
        """Messages that did not decode (or of another type), by topic; not logged."""
        return self.node.drops

    def resolve(self, topic: str) -> str:
        """The fully qualified name of ``topic`` (``ValueError`` if it is not a topic name)."""
        return self.names.resolve(topic)

    def _on_graph(self, entity: Entity, alive: bool) -> None:
        self._touch()

    def _touch(self) -> None:
        with self._changed:
            self._last_change = time.monotonic()
            self._changed.notify_all()

    def connected(self) -> bool:
        """Whether the session reaches a peer or a router."""
        info = self.session.info
        return bool(list(info.peers_zid()) or list(info.routers_zid()))

    def settle(self, timeout: float, quiet: float = QUIET_S) -> bool:
        """Wait until the graph is complete: the session reached a peer or router, every
        reachable token answered a liveliness query, and no token changed for ``quiet`` s.
        Returns whether a peer or router was reached within ``timeout`` s."""
        deadline = time.monotonic() + timeout
        while not self.connected():
            if time.monotonic() >= deadline:
                log.info("no Zenoh peer or router reached in %.1f s", timeout)
                return False
            time.sleep(0.02)
        key = f"{ADMIN_SPACE}/{self.graph.domain_id}/**"
        remaining = max(0.1, deadline - time.monotonic())
        for reply in self.session.liveliness().get(key, timeout=remaining):
            if reply.ok is not None:
                if self.graph.update(str(reply.ok.key_expr), True) is not None:
                    self._touch()
        with self._changed:
            while True:
                now = time.monotonic()
                wait = min(self._last_change + quiet, deadline) - now
                if wait <= 0:
                    return True
                self._changed.wait(wait)

    def publishers(self, topic: str, timeout: float | None) -> list[Entity]:
        """The publishers of the fully qualified ``topic``, waiting up to ``timeout`` s (``None``:
        without end) for one to appear; empty when none did."""
        deadline = None if timeout is None else time.monotonic() + timeout
        with self._changed:
            while True:
                found = self.graph.endpoints(topic, "MP")
                if found:
                    return sorted(found, key=lambda e: e.node_fqn)
                wait = 1.0 if deadline is None else deadline - time.monotonic()
                if wait <= 0:
                    return []
                self._changed.wait(min(wait, 1.0))

    def subscribe(self, topic: str, ros_type: str, handler: Handler,
                  raw: bool = False) -> Subscription:
        """Subscribe to the fully qualified ``topic`` (see :meth:`resolve`) as ``ros_type``
        and declare the node.

        Raises:
            MessageError: ``ros_type`` is not in the type store.
        """
        sub = self.node.subscription(topic, ros_type, handler, raw=raw)
        self.node.announce()
        log.debug("subscribed to %s as %s", topic, ros_type)
        return sub

    def close(self) -> None:
        """Close the inspector's node (its subscriptions and token); the session stays open."""
        self.node.close()


def message_to_plain(msg: Any, truncate: int | None = None) -> Any:
    """A message as plain data (dicts in field order, lists, numbers, strings): what
    ``ros2 topic echo`` shows. Arrays and strings longer than ``truncate`` are cut, with
    ``'...'`` as their last item (or suffix)."""
    if is_dataclass(msg) and not isinstance(msg, type):
        return {f.name: message_to_plain(getattr(msg, f.name), truncate) for f in fields(msg)
                if not _class_level(f.type)}
    if isinstance(msg, np.ndarray):
        return _cut(msg.tolist(), truncate)
    if isinstance(msg, list | tuple):
        return _cut([message_to_plain(v, truncate) for v in msg], truncate)
    if isinstance(msg, np.generic):
        return msg.item()
    if isinstance(msg, bytes):
        return _cut(list(msg), truncate)
    if isinstance(msg, str) and truncate is not None and len(msg) > truncate:
        return msg[:truncate] + "..."
    return msg


def _class_level(annotation: object) -> bool:
    # rosbags declares a message's constants and ``__msgtype__`` as ClassVar fields (by name).
    return str(annotation).startswith(("ClassVar", "typing.ClassVar"))


def _cut(items: list, truncate: int | None) -> list:
    if truncate is not None and len(items) > truncate:
        return [*items[:truncate], "..."]
    return items


def json_safe(value: Any) -> Any:
    """``value`` (plain data) with non-finite floats as the strings ``nan``, ``inf`` and
    ``-inf``, which strict JSON cannot hold as numbers."""
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, list):
        return [json_safe(v) for v in value]
    return value


@dataclass(frozen=True)
class RateStats:
    """A topic's rate over a window of messages, as ``ros2 topic hz`` reports it.

    Attributes:
        rate: Average rate (Hz): one over the mean period.
        min_period: Shortest period in the window (s).
        max_period: Longest period (s).
        std_dev: Standard deviation of the periods (s).
        window: Number of periods.
    """

    rate: float
    min_period: float
    max_period: float
    std_dev: float
    window: int


class RateWindow:
    """Receipt times of the last ``window`` + 1 messages and the statistics of their periods
    (thread-safe: messages arrive on Zenoh's thread)."""

    def __init__(self, window: int = 10000, clock: Callable[[], float] = time.monotonic) -> None:
        if window < 1:
            raise ValueError(f"the window holds at least 1 period, got {window}")
        self.clock = clock
        self.count = 0
        self._times: deque[float] = deque(maxlen=window + 1)
        self._lock = threading.Lock()

    def tick(self, t: float | None = None) -> None:
        """One message received at ``t`` (default: now on :attr:`clock`)."""
        now = self.clock() if t is None else t
        with self._lock:
            self._times.append(now)
            self.count += 1

    def stats(self) -> RateStats | None:
        """The statistics of the window; ``None`` before two messages."""
        with self._lock:
            times = np.fromiter(self._times, float)
        if times.size < 2:
            return None
        periods = np.diff(times)
        mean = float(periods.mean())
        return RateStats(1.0 / mean if mean > 0 else math.inf, float(periods.min()),
                         float(periods.max()), float(periods.std()), int(periods.size))
