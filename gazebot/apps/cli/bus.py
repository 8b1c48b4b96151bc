"""Command-line options shared by the bus nodes (``gazebot sim``, ``gazebot run``, ``gazebot
display``): how a node joins the Zenoh bus and names its ROS 2 topics."""

from __future__ import annotations

import argparse
import os

from gazebot.apps.cli.errors import UsageError
from gazebot.io.drivers.rmw.names import Names, parse_remap
from gazebot.io.drivers.session import DEFAULT_ENDPOINT, EPHEMERAL_ENDPOINT, BusConfig
from gazebot.io.ros2.convert import BODIES


def _tf_frame(value: str) -> tuple[str, str]:
    body, sep, frame = value.partition("=")
    if not sep or body not in BODIES or not frame:
        raise argparse.ArgumentTypeError(
            f"expected BODY=FRAME with BODY one of {', '.join(BODIES)}, got {value!r}")
    return body, frame


def _remap(value: str) -> tuple[str, str]:
    try:
        return parse_remap(value)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _domain_id(value: str) -> int:
    try:
        d = int(value)
    except ValueError:
        d = -1
    if not 0 <= d <= 232:
        raise argparse.ArgumentTypeError(f"expected a ROS domain id 0..232, got {value!r}")
    return d


def add_bus_arguments(parser: argparse.ArgumentParser, listens_by_default: bool) -> None:
    """``--namespace``, ``--remap``, ``--domain-id``, ``--base-frame``, ``--tf-frame``,
    ``--listen``, ``--connect``, ``--multicast``, ``--zenoh-config``: how the node joins the
    bus.

    By default the robot side (``gazebot sim``) listens on ``tcp/127.0.0.1:7447`` and engine
    nodes (``gazebot run``) connect to it, listening on an ephemeral port so that other
    connected nodes reach them too. ``--connect tcp/HOST:7447`` joins a Zenoh router instead.
    """
    listen_default = DEFAULT_ENDPOINT if listens_by_default else EPHEMERAL_ENDPOINT
    connect_default = "none" if listens_by_default else DEFAULT_ENDPOINT
    parser.add_argument("--namespace", default="/gazebot", metavar="NS",
                        help="ROS namespace of the nodes and their relative topics "
                        "(default /gazebot)")
    parser.add_argument("--remap", action="append", type=_remap, default=[],
                        metavar="FROM:=TO", help="rename a topic, repeatable "
                        "(e.g. gaze_target:=/robot/look_at)")
    parser.add_argument("--domain-id", type=_domain_id, default=None, metavar="N",
                        help="ROS domain id (default: $ROS_DOMAIN_ID, else 0)")
    parser.add_argument("--base-frame", default=None, metavar="FRAME",
                        help="TF name of the robot base frame: frame_id of the points sent "
                        "and accepted (default: the robot YAML's base_frame)")
    parser.add_argument("--tf-frame", action="append", type=_tf_frame, default=[],
                        metavar="BODY=FRAME", help="also take BODY (giver_hand, receiver_hand, "
                        "giver_face) from /tf: FRAME's transform from the base frame; repeatable")
    parser.add_argument(
        "--listen",
        action="append",
        metavar="EP",
        help=f"endpoint to listen on, repeatable (default: {listen_default})",
    )
    parser.add_argument(
        "--connect",
        action="append",
        metavar="EP",
        help=f"peer or router endpoint to connect to, e.g. tcp/HOST:7447, repeatable "
        f"(default: {connect_default})",
    )
    parser.add_argument(
        "--multicast", action="store_true", help="enable multicast scouting (off by default)"
    )
    add_zenoh_config_argument(parser)


def add_zenoh_config_argument(parser: argparse.ArgumentParser) -> None:
    """``--zenoh-config FILE``: a Zenoh JSON5 configuration as the base of the session's."""
    parser.add_argument(
        "--zenoh-config", metavar="FILE", default=None,
        help="Zenoh JSON5 configuration file the session starts from: TLS certificates "
        "(transport.link.tls), user/password authentication (transport.auth.usrpwd), access "
        "control; its listen/connect endpoints are used unless --listen/--connect are given",
    )


def zenoh_file_settings(path: str | None, mode: str
                        ) -> tuple[str, tuple[str, ...], tuple[str, ...]]:
    """``(mode, listen, connect)`` of a ``--zenoh-config`` file: its ``peer`` or ``client``
    mode if it sets one (else ``mode``) and the endpoints it sets (empty when it sets none, or
    without a file). A bad file is a :class:`UsageError` naming it."""
    if path is None:
        return mode, (), ()
    import json

    from gazebot.io.drivers.session import file_endpoints, load_zenoh_config

    try:
        cfg = load_zenoh_config(path)
    except ValueError as exc:
        raise UsageError(f"--zenoh-config {exc}") from None
    file_mode = json.loads(cfg.get_json("mode"))
    if mode != "router" and file_mode in ("peer", "client"):
        mode = file_mode
    return (mode, file_endpoints(cfg, "listen/endpoints", mode),
            file_endpoints(cfg, "connect/endpoints", mode))


def add_record_argument(parser: argparse.ArgumentParser) -> None:
    """``--record FILE.mcap``: record the bus to MCAP while the node runs."""
    parser.add_argument("--record", metavar="FILE.mcap", default=None,
                        help="record every gazebot topic on the bus (ROS 2 schemas embedded, "
                        "log time = receive time) to this MCAP file, as ros2 bag record does")


def bus_names(args: argparse.Namespace, base_frame: str = "world") -> Names:
    """The :class:`Names` of parsed ``add_bus_arguments`` options (``ValueError`` if bad);
    ``base_frame``: the robot's, unless ``--base-frame`` names another."""
    domain = args.domain_id
    if domain is None:
        env = os.environ.get("ROS_DOMAIN_ID", "").strip()
        domain = _domain_id(env) if env else 0
    return Names(args.namespace, dict(args.remap), domain,
                 base_frame=args.base_frame or base_frame, tf_frames=dict(args.tf_frame))


def robot_base_frame(robot: str) -> str:
    """The base frame of robot ``robot`` (name or YAML file) as its YAML names it."""
    from gazebot.core.kinematics.robot_config import load_robot_config

    return load_robot_config(robot)[0].base_frame


def bus_config(args: argparse.Namespace, listens_by_default: bool,
               base_frame: str = "world") -> BusConfig:
    """The :class:`BusConfig` of parsed ``add_bus_arguments`` options (``base_frame``: the
    robot's, see :func:`bus_names`)."""
    mode, file_listen, file_connect = zenoh_file_settings(args.zenoh_config, "peer")
    listen = args.listen if args.listen is not None else (file_listen or (
        [DEFAULT_ENDPOINT] if listens_by_default else [EPHEMERAL_ENDPOINT]))
    connect = args.connect if args.connect is not None else (file_connect or (
        [] if listens_by_default else [DEFAULT_ENDPOINT]))
    try:
        return BusConfig(
            names=bus_names(args, base_frame),
            listen=tuple(listen),
            connect=tuple(connect),
            multicast_scouting=args.multicast,
            mode=mode,  # type: ignore[arg-type]
            config_file=args.zenoh_config,
        )
    except ValueError as exc:
        raise UsageError(str(exc)) from None


def bus_failure(exc: BaseException) -> str | None:
    """The one-line message for a node that could not join the Zenoh bus (``None``: ``exc``
    is something else). Found by the ``zenoh.ZError`` in the exception's chain, so it holds
    whatever the driver wraps it in; the endpoint already in use (a second ``gazebot sim``)
    gets its own advice."""
    import re
    import sys

    zenoh = sys.modules.get("zenoh")
    z_error = getattr(zenoh, "ZError", None) if zenoh is not None else None
    if z_error is None:
        return None
    seen: set[int] = set()
    cause: BaseException | None = exc
    while cause is not None and id(cause) not in seen and not isinstance(cause, z_error):
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__
    if cause is None or not isinstance(cause, z_error):
        return None
    text = re.sub(r"\s+at /\S+\.rs:\d+\.?", "", str(cause)).strip()  # Zenoh's Rust sources
    taken = re.search(r"bound to (\S+?):\s*\[", text)
    if "Address already in use" in text and taken:
        return (
            f"cannot listen on {taken.group(1)}: the address is already in use (another gazebot "
            "sim on this port?); stop it, or pass --listen with another port and --connect "
            "to it from the other nodes"
        )
    return f"could not join the Zenoh bus: {text}"
