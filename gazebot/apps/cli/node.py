"""``gazebot node``: the ROS 2 nodes on the Zenoh bus (gazebot's and any rmw_zenoh node's), as
``ros2 node list`` shows them, from their liveliness tokens."""

from __future__ import annotations

import argparse

from gazebot.apps.cli.bus import add_bus_arguments
from gazebot.apps.cli.topic import add_graph_timeout, inspector, settled


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("node", help="list the ROS 2 nodes on the bus (like ros2 node list)",
                       description="The ROS 2 nodes on the Zenoh bus, without ROS 2.")
    cmds = p.add_subparsers(dest="node_command", metavar="COMMAND")
    cmds.required = True
    ls = cmds.add_parser("list", help="the nodes' fully qualified names")
    ls.add_argument("-a", "--all", action="store_true",
                    help="also hidden nodes (names starting with _, such as command-line tools)")
    ls.add_argument("-c", "--count-nodes", action="store_true", help="print only their number")
    add_graph_timeout(ls)
    add_bus_arguments(ls, listens_by_default=False)
    ls.set_defaults(func=list_nodes)


def list_nodes(args: argparse.Namespace) -> int:
    with inspector(args) as insp:
        reached = settled(insp, args)
        names = sorted({n.node_fqn for n in insp.graph.nodes()
                        if args.all or not n.node.startswith("_")})
    if args.count_nodes:
        print(len(names))
    else:
        for name in names:
            print(name)
    return 0 if reached else 1
