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

A secured bus: ``config_file`` names a Zenoh JSON5 configuration (TLS certificates under
``transport/link/tls``, user/password under ``transport/auth/usrpwd``, ``access_control``...)
that is the base of the session's configuration; gazebot sets on top only its mode, its
endpoints and, where the file leaves them unset, multicast scouting (off) and the reconnection
back-off.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Literal

from gazebot.io.drivers.rmw.names import Names

if TYPE_CHECKING:
    import zenoh

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
EPHEMERAL_ENDPOINT = "tcp/127.0.0.1:0"
#: Largest message Zenoh reassembles for a gazebot node (bytes): twice the largest topic cap
#: (eye images, 4 MiB); Zenoh's own default is 1 GiB. A larger message is dropped by Zenoh,
#: the link stays up.
MAX_MESSAGE_BYTES = 8 * 1024 * 1024
#: Where ``gazebot router`` listens by default (every interface, rmw_zenohd's port).
#: ``gazebot router``'s default: loopback only. The router has no authentication unless a
#: ``--zenoh-config`` sets it up, so opening it to the network takes an explicit ``--listen``.
ROUTER_ENDPOINT = "tcp/127.0.0.1:7447"
_ENDPOINT = re.compile(r"^(tcp|udp|tls|quic|ws|unixsock-stream|serial)/\S+$")


def _one_line(exc: BaseException) -> str:
    """Zenoh's error text on one line, without its Rust source locations."""
    return " ".join(re.sub(r"\s+at /\S+\.rs:\d+\.?", "", str(exc)).split())


def load_zenoh_config(path: str | Path) -> zenoh.Config:
    """The Zenoh configuration in the JSON5 file ``path``; ``ValueError`` naming the file and
    what Zenoh found wrong (a missing file, bad JSON5, an unknown key), in one line."""
    import zenoh

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such Zenoh configuration file")
    try:
        return zenoh.Config.from_file(str(path))
    except zenoh.ZError as exc:
        raise ValueError(f"{path}: not a valid Zenoh configuration: {_one_line(exc)}") from None


def _unset(cfg: zenoh.Config, key: str) -> bool:
    """Whether ``cfg`` leaves ``key`` at Zenoh's default (the file does not set it)."""
    import zenoh

    return cfg.get_json(key) == zenoh.Config().get_json(key)


def file_endpoints(cfg: zenoh.Config, key: str, mode: str) -> tuple[str, ...]:
    """The endpoints a configuration sets under ``key`` (``listen/endpoints`` or
    ``connect/endpoints``) for ``mode`` (a per-mode map picks ``mode``'s); ``()`` when it
    leaves them at Zenoh's default."""
    if _unset(cfg, key):
        return ()
    value = json.loads(cfg.get_json(key))
    if isinstance(value, dict):
        value = value.get(mode, [])
    return tuple(str(v) for v in value or ())


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
        config_file: A Zenoh JSON5 configuration file, the base of the session's (TLS,
            authentication, access control); ``None``: Zenoh's defaults.
        max_message_bytes: Largest message Zenoh reassembles for a peer or client (a router
            forwards others' traffic and keeps Zenoh's default), unless the file sets
            ``transport/link/rx/max_message_size``.
    """

    names: Names = field(default_factory=Names)
    listen: tuple[str, ...] = (DEFAULT_ENDPOINT,)
    connect: tuple[str, ...] = ()
    mode: Literal["peer", "client", "router"] = "peer"
    multicast_scouting: bool = False
    retry_max_s: float = 1.0
    config_file: str | None = None
    max_message_bytes: int = MAX_MESSAGE_BYTES

    def __post_init__(self) -> None:
        if not isinstance(self.names, Names):
            raise ValueError(f"names must be a Names, got {self.names!r}")
        for ep in (*self.listen, *self.connect):
            check_endpoint(ep)
        if self.mode not in ("peer", "client", "router"):
            raise ValueError(f"mode must be 'peer', 'client' or 'router', got {self.mode!r}")
        if self.mode == "client" and not self.connect:
            raise ValueError("client mode needs a router endpoint in 'connect'")
        if not (isinstance(self.max_message_bytes, int) and self.max_message_bytes > 0):
            raise ValueError(
                f"max_message_bytes must be a positive integer, got {self.max_message_bytes!r}")
        if not self.retry_max_s > 0:
            raise ValueError(f"retry_max_s must be > 0, got {self.retry_max_s!r}")

    def zenoh_config(self) -> zenoh.Config:
        """The equivalent :class:`zenoh.Config`."""
        import zenoh

        cfg = load_zenoh_config(self.config_file) if self.config_file else zenoh.Config()
        from_file = self.config_file is not None
        cfg.insert_json5("mode", json.dumps(self.mode))
        cfg.insert_json5("listen/endpoints", json.dumps(list(self.listen)))
        cfg.insert_json5("connect/endpoints", json.dumps(list(self.connect)))
        if self.multicast_scouting or not from_file or _unset(cfg, "scouting/multicast/enabled"):
            cfg.insert_json5("scouting/multicast/enabled", json.dumps(self.multicast_scouting))
        rx_max = "transport/link/rx/max_message_size"
        if self.mode != "router" and (not from_file or _unset(cfg, rx_max)):
            cfg.insert_json5(rx_max, json.dumps(int(self.max_message_bytes)))
        if from_file and not _unset(cfg, "connect/retry"):
            return cfg
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
    naming the endpoints (and the configuration file)."""
    import zenoh

    try:
        return zenoh.open(config.zenoh_config())
    except zenoh.ZError as exc:
        file = f", config {config.config_file}" if config.config_file else ""
        raise ValueError(
            f"could not open a Zenoh session (listen={list(config.listen)}, "
            f"connect={list(config.connect)}{file}): {exc}"
        ) from exc
