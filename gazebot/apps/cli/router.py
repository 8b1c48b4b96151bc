"""``gazebot router``: a Zenoh router for machines without ``zenohd`` or rmw_zenoh's
``rmw_zenohd``. gazebot nodes and ROS 2 nodes (rmw_zenoh) join it with
``--connect tcp/HOST:7447``; it routes their data and liveliness (the ROS graph)."""

from __future__ import annotations

import argparse
import sys
import threading

from gazebot.apps.cli.argtypes import positive
from gazebot.apps.cli.bus import add_zenoh_config_argument, zenoh_file_settings
from gazebot.apps.cli.errors import UsageError
from gazebot.io.drivers.session import ROUTER_ENDPOINT, BusConfig, open_session


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "router",
        help="run a Zenoh router that gazebot and ROS 2 (rmw_zenoh) nodes connect to",
        description="Start a router-mode Zenoh session: nodes started with --connect "
        "tcp/HOST:7447 meet through it, as rmw_zenoh deployments do with rmw_zenohd.",
    )
    p.add_argument("--listen", action="append", metavar="EP",
                   help=f"endpoint to listen on, repeatable (default: {ROUTER_ENDPOINT}, this "
                   "machine only; e.g. tcp/0.0.0.0:7447 opens it to the network, without "
                   "authentication unless --zenoh-config sets it up)")
    p.add_argument("--connect", action="append", default=[], metavar="EP",
                   help="another router to connect to, repeatable")
    p.add_argument("--duration", type=positive, default=None,
                   help="seconds to run (default: until Ctrl-C)")
    add_zenoh_config_argument(p)
    p.set_defaults(func=handle)


def router_config(args: argparse.Namespace) -> BusConfig:
    """The router's bus: ``--listen`` endpoints, else the ``--zenoh-config`` file's, else
    :data:`~gazebot.io.drivers.session.ROUTER_ENDPOINT` (loopback only)."""
    _, file_listen, file_connect = zenoh_file_settings(args.zenoh_config, "router")
    try:
        return BusConfig(listen=tuple(args.listen or file_listen or [ROUTER_ENDPOINT]),
                         connect=tuple(args.connect or file_connect), mode="router",
                         config_file=args.zenoh_config)
    except ValueError as exc:
        raise UsageError(str(exc)) from None


def handle(args: argparse.Namespace) -> int:
    cfg = router_config(args)
    try:
        session = open_session(cfg)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    try:
        print(f"gazebot router: listening on {list(cfg.listen)} (zid {session.info.zid()})",
              file=sys.stderr, flush=True)
        try:
            threading.Event().wait(args.duration)
        except KeyboardInterrupt:
            pass  # Ctrl-C ends the run early, as --duration would; the router closes below
    finally:
        session.close()
    return 0
