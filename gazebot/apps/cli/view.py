"""``gazebot view``: the handover live in a browser, without ROS 2. It joins the bus as a node
(``view``) and serves what the engine publishes for rviz2 (``/tf``, ``/tf_static``,
``markers``) and the phase, gaze target, tracked points, head commands and events over the
Foxglove WebSocket protocol (Foxglove SDK, ``foxglove-sdk``): open Foxglove, "Open connection",
``ws://HOST:PORT``, and a 3D panel shows gaze, hands and face as the handover runs.

Messages go through as they came off the bus: ROS 2 CDR (``cdr``) with the type's ``ros2msg``
definition as schema, so Foxglove decodes them as it does a ROS 2 bag. A latched topic's last
message is sent again to a client that subscribes to it later.
"""

from __future__ import annotations

import argparse
import json
import sys
import threading
import time
from typing import Any

from gazebot.apps.cli.argtypes import positive
from gazebot.apps.cli.bus import add_bus_arguments, bus_config
from gazebot.apps.cli.errors import UsageError
from gazebot.io.ros2 import topics
from gazebot.io.ros2.topics import Topic

#: The topics the view serves.
VIEW_TOPICS: tuple[Topic, ...] = (
    topics.TF, topics.TF_STATIC, topics.MARKERS, topics.PHASE, topics.GAZE_TARGET,
    topics.GIVER_HAND, topics.RECEIVER_HAND, topics.GIVER_FACE, topics.HEAD_COMMAND,
    topics.EVENTS,
)
DEFAULT_PORT = 8765
INSTALL_HINT = "gazebot view needs the [view] extra (the Foxglove SDK): pip install 'gazebot[view]'"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "view",
        help="serve the running handover live to Foxglove (WebSocket), no ROS 2 needed",
        description="Join the bus and serve /tf, /tf_static, the markers (gaze ray, gaze "
        "target, hands, face, phase), the phase, gaze target, tracking, head commands and "
        "events live over the Foxglove WebSocket protocol: in Foxglove, open a connection to "
        "ws://HOST:PORT. Needs the [view] extra (the Foxglove SDK).",
    )
    p.add_argument("--port", type=int, default=DEFAULT_PORT,
                   help=f"WebSocket port (default {DEFAULT_PORT}; 0: any free port)")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to serve on (default 127.0.0.1; 0.0.0.0 for other machines)")
    p.add_argument("--duration", type=positive, default=None, metavar="S",
                   help="seconds to run (default: until Ctrl-C)")
    p.add_argument("--json", action="store_true", help="print a JSON summary at the end")
    add_bus_arguments(p, listens_by_default=False)
    p.set_defaults(func=handle)


class LiveView:
    """Forwards the bus's view topics to a Foxglove WebSocket server.

    Args:
        session: An open Zenoh session (not closed by :meth:`close`).
        names: Namespace, remapping and domain of the topics.
        host, port: Where the WebSocket server listens (``port`` 0: any free port).
        name: The node's name on the bus.

    Raises:
        UsageError: The Foxglove SDK is not installed.
    """

    def __init__(self, session: Any, names: Any, host: str = "127.0.0.1",
                 port: int = DEFAULT_PORT, name: str = "view") -> None:
        try:
            import foxglove
        except ImportError:
            raise UsageError(INSTALL_HINT) from None
        from gazebot.io.drivers.rmw.node import RosNode

        if not 0 <= port <= 65535:
            raise UsageError(f"--port must be 0..65535, got {port}")
        self.context = foxglove.Context()
        self.ros = RosNode(session, names, name)
        self.forwarded: dict[str, int] = {}
        self._lock = threading.Lock()
        self._latched: dict[str, tuple[bytes, int]] = {}
        self._channels: dict[str, Any] = {}
        self._by_id: dict[int, str] = {}
        try:
            for topic in VIEW_TOPICS:
                self._forward(foxglove, topic)
            self.ros.announce()
            self.server = foxglove.start_server(
                name="gazebot", host=host, port=port, context=self.context,
                server_listener=_relatch_listener(self))
        except BaseException:
            self.ros.close()
            raise
        self.port = self.server.port

    def _forward(self, foxglove: Any, topic: Topic) -> None:
        resolved = self.ros.names.resolve(topic.name)
        definition, _ = self.ros.store.generate_msgdef(topic.type, ros_version=2)
        channel = foxglove.Channel(
            resolved, message_encoding="cdr", context=self.context,
            schema=foxglove.Schema(name=topic.type, encoding="ros2msg",
                                   data=definition.encode()))
        self._channels[resolved] = channel
        self._by_id[channel.id()] = resolved
        latched = topic.durability == "transient_local"

        def on(data: bytes, received: Any) -> None:
            stamp = received.attachment.source_timestamp if received.attachment else time.time_ns()
            with self._lock:
                self.forwarded[resolved] = self.forwarded.get(resolved, 0) + 1
                if latched:
                    self._latched[resolved] = (data, stamp)
            channel.log(data, log_time=stamp)

        self.ros.subscription(topic.name, topic.type, on, raw=True)

    def relatch(self, channel_id: int) -> None:
        """Send a latched topic's last message again (a client just subscribed to it)."""
        topic = self._by_id.get(channel_id)
        with self._lock:
            last = self._latched.get(topic) if topic is not None else None
        if last is not None and topic is not None:
            self._channels[topic].log(last[0], log_time=last[1])

    def close(self) -> None:
        self.server.stop()
        self.ros.close()


def _relatch_listener(view: LiveView) -> Any:
    """The server listener that re-sends a latched topic's last message to a client that
    subscribes to it."""
    from foxglove.websocket import ServerListener

    class Relatch(ServerListener):
        def on_subscribe(self, client: Any, channel: Any) -> None:
            view.relatch(channel.id)

    return Relatch()


def handle(args: argparse.Namespace) -> int:
    from gazebot.io.drivers.session import open_session

    cfg = bus_config(args, listens_by_default=False)
    session = open_session(cfg)
    view = None
    try:
        view = LiveView(session, cfg.names, args.host, args.port)
        print(f"gazebot view: ws://{args.host}:{view.port} (Foxglove: Open connection) serving "
              f"{len(VIEW_TOPICS)} topics under {cfg.names.namespace} "
              f"(connect {list(cfg.connect)})", file=sys.stderr, flush=True)
        stop = threading.Event()
        try:
            stop.wait(args.duration)
        except KeyboardInterrupt:
            pass  # Ctrl-C is how a user stops it: the closing lines below still run
        summary = {"forwarded": dict(sorted(view.forwarded.items())),
                   "dropped": view.ros.drops.counts()}
    finally:
        if view is not None:
            view.close()
        session.close()
    print(json.dumps(summary) if args.json else "\n".join(f"{k}: {v}" for k, v in summary.items()))
    return 0
