"""Zenoh session configuration for gazebot nodes.

Defaults keep a node on this machine: peer mode, multicast scouting off, and the robot side
(``gazebot sim`` or a robot bridge) listening on ``tcp/127.0.0.1:7447`` while engine nodes
(``gazebot run``) connect to it and listen on an ephemeral port (:data:`EPHEMERAL_ENDPOINT`).
Peers do not forward traffic between other peers: a node that connects must also listen
somewhere, so that gossip scouting can mesh it with the other connected nodes (an engine and a
monitor both connected to the simulator then see each other).

In a ROS 2 deployment every node connects to a Zenoh router instead (``zenohd``, rmw_zenoh's
``rmw_zenohd``, or ``gazebot router``): ``connect=("tcp/<router>:7447",)``, as rmw_zenoh's
nodes do.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

from gazebot.drivers.rmw.names import Names

if TYPE_CHECKING:
    import zenoh

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
EPHEMERAL_ENDPOINT = "tcp/127.0.0.1:0"
#: Where ``gazebot router`` listens by default (every interface, rmw_zenohd's port).
ROUTER_ENDPOINT = "tcp/0.0.0.0:7447"
_ENDPOINT = re.compile(r"^(tcp|udp|tls|quic|ws|unixsock-stream|serial)/\S+$")


def check_endpoint(endpoint: str) -> str:
    """Return ``endpoint`` if it looks like a Zenoh locator (``tcp/HOST:PORT``), else raise."""
    if not isinstance(endpoint, str) or not _ENDPOINT.match(endpoint):
        raise ValueError(
            f"bad Zenoh endpoint {endpoint!r}: expected PROTOCOL/ADDRESS, e.g. {DEFAULT_ENDPOINT}"
        )
    return endpoint


@dataclass(frozen=True)
class BusConfig:
    """How a node joins the bus.

    Attributes:
        names: Namespace (default ``/gazebot``), topic remapping, ROS domain id and frame
            names of the node's topics.
        listen: Endpoints this node accepts connections on.
        connect: Endpoints this node connects to (other peers or a router); retried in the
            background until they answer.
        mode: ``peer`` (default), ``client`` (through a router given in ``connect``) or
            ``router`` (``gazebot router``).
        multicast_scouting: Discover peers by UDP multicast (off: only explicit endpoints).
        retry_max_s: Upper bound of the reconnection back-off (s), so a restarted peer is found
            again quickly.
    """

    names: Names = field(default_factory=Names)
    listen: tuple[str, ...] = (DEFAULT_ENDPOINT,)
    connect: tuple[str, ...] = ()
    mode: Literal["peer", "client", "router"] = "peer"
    multicast_scouting: bool = False
    retry_max_s: float = 1.0

    def __post_init__(self) -> None:
        if not isinstance(self.names, Names):
            raise ValueError(f"names must be a Names, got {self.names!r}")
        for ep in (*self.listen, *self.connect):
            check_endpoint(ep)
        if self.mode not in ("peer", "client", "router"):
            raise ValueError(f"mode must be 'peer', 'client' or 'router', got {self.mode!r}")
        if self.mode == "client" and not self.connect:
            raise ValueError("client mode needs a router endpoint in 'connect'")
        if not self.retry_max_s > 0:
            raise ValueError(f"retry_max_s must be > 0, got {self.retry_max_s!r}")

    def zenoh_config(self) -> zenoh.Config:
        """The equivalent :class:`zenoh.Config`."""
        import zenoh

        cfg = zenoh.Config()
        cfg.insert_json5("mode", json.dumps(self.mode))
        cfg.insert_json5("listen/endpoints", json.dumps(list(self.listen)))
        cfg.insert_json5("connect/endpoints", json.dumps(list(self.connect)))
        cfg.insert_json5("scouting/multicast/enabled", json.dumps(self.multicast_scouting))
        retry_max_ms = max(100, int(self.retry_max_s * 1000))
        cfg.insert_json5(
            "connect/retry",
            json.dumps(
                {
                    "period_init_ms": min(100, retry_max_ms),
                    "period_max_ms": retry_max_ms,
                    "period_increase_factor": 2,
                }
            ),
        )
        return cfg


def open_session(config: BusConfig) -> zenoh.Session:
    """Open a Zenoh session for ``config``; a bind or config failure raises ``ValueError``
    naming the endpoints."""
    import zenoh

    try:
        return zenoh.open(config.zenoh_config())
    except zenoh.ZError as exc:
        raise ValueError(
            f"could not open a Zenoh session (listen={list(config.listen)}, "
            f"connect={list(config.connect)}): {exc}"
        ) from exc
