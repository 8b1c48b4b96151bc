"""Command-line options shared by the bus nodes (``gazebot sim``, ``gazebot run``, ``gazebot
display``): how a node joins the Zenoh bus, and positive numbers."""

from __future__ import annotations

import argparse

from gazebot.drivers.session import DEFAULT_ENDPOINT, EPHEMERAL_ENDPOINT, BusConfig


def add_bus_arguments(parser: argparse.ArgumentParser, listens_by_default: bool) -> None:
    """``--id``, ``--listen``, ``--connect``, ``--multicast``: how the node joins the bus.

    By default the robot side (``gazebot sim``) listens on ``tcp/127.0.0.1:7447`` and engine
    nodes (``gazebot run``) connect to it, listening on an ephemeral port so that other
    connected nodes reach them too.
    """
    listen_default = DEFAULT_ENDPOINT if listens_by_default else EPHEMERAL_ENDPOINT
    connect_default = "none" if listens_by_default else DEFAULT_ENDPOINT
    parser.add_argument("--id", default="sim", help="robot id: keys live under gazebot/<id>/")
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
        help=f"peer or router endpoint to connect to, repeatable (default: {connect_default})",
    )
    parser.add_argument(
        "--multicast", action="store_true", help="enable multicast scouting (off by default)"
    )


def bus_config(args: argparse.Namespace, listens_by_default: bool) -> BusConfig:
    """The :class:`BusConfig` of parsed ``add_bus_arguments`` options."""
    listen = args.listen if args.listen is not None else (
        [DEFAULT_ENDPOINT] if listens_by_default else [EPHEMERAL_ENDPOINT])
    connect = args.connect if args.connect is not None else (
        [] if listens_by_default else [DEFAULT_ENDPOINT])
    return BusConfig(
        robot_id=args.id,
        listen=tuple(listen),
        connect=tuple(connect),
        multicast_scouting=args.multicast,
    )


def positive(value: str) -> float:
    try:
        x = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {value!r}") from None
    if not x > 0 or x != x:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {value!r}")
    return x


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
