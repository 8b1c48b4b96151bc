"""Zenoh session configuration for gazebot nodes.

Defaults keep a node on this machine: peer mode, multicast scouting off, and the robot side
(``gazebot sim`` or a robot bridge) listening on ``tcp/127.0.0.1:7447`` while engine nodes
(``gazebot run``) connect to it and listen on an ephemeral port (:data:`EPHEMERAL_ENDPOINT`).
Peers do not forward traffic between other peers: a node that connects must also listen
somewhere, so that gossip scouting can mesh it with the other connected nodes (an engine and a
monitor both connected to the simulator then see each other). For several machines, listen on a
routable address or connect every node to a Zenoh router (``connect=("tcp/<router>:7447",)``,
optionally ``mode="client"``).
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from gazebot.drivers.keys import KeyLayout, check_chunk

if TYPE_CHECKING:
    import zenoh

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
EPHEMERAL_ENDPOINT = "tcp/127.0.0.1:0"
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
        robot_id: The robot's key chunk: topics live under ``gazebot/<robot_id>/``.
        listen: Endpoints this node accepts connections on.
        connect: Endpoints this node connects to (other peers or a router); retried in the
            background until they answer.
        mode: ``peer`` (default) or ``client`` (through a router given in ``connect``).
        multicast_scouting: Discover peers by UDP multicast (off: only explicit endpoints).
        retry_max_s: Upper bound of the reconnection back-off (s), so a restarted peer is found
            again quickly.
    """

    robot_id: str = "sim"
    listen: tuple[str, ...] = (DEFAULT_ENDPOINT,)
    connect: tuple[str, ...] = ()
    mode: Literal["peer", "client"] = "peer"
    multicast_scouting: bool = False
    retry_max_s: float = 1.0

    def __post_init__(self) -> None:
        check_chunk(self.robot_id, "robot id")
        for ep in (*self.listen, *self.connect):
            check_endpoint(ep)
        if self.mode not in ("peer", "client"):
            raise ValueError(f"mode must be 'peer' or 'client', got {self.mode!r}")
        if self.mode == "client" and not self.connect:
            raise ValueError("client mode needs a router endpoint in 'connect'")
        if not self.retry_max_s > 0:
            raise ValueError(f"retry_max_s must be > 0, got {self.retry_max_s!r}")

    @property
    def keys(self) -> KeyLayout:
        return KeyLayout(self.robot_id)

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
