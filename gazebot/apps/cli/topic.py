"""``gazebot topic``: inspect the ROS 2 topics on the Zenoh bus without ROS 2, as ``ros2 topic``
does: ``list``, ``info``, ``echo`` (decoded by the type the publisher advertises, any ROS 2 Jazzy
standard type or ``gazebot_msgs``) and ``hz``. Works with gazebot's nodes and any rmw_zenoh node.

Relative topic names resolve in ``--namespace`` (``/gazebot`` by default), as gazebot's own
nodes name them: ``gazebot topic echo gaze_target`` is ``/gazebot/gaze_target``."""

from __future__ import annotations

import argparse
import contextlib
import json
import queue
import sys
import time
from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING, Any

from gazebot.apps.cli.argtypes import int_at_least, positive
from gazebot.apps.cli.bus import add_bus_arguments, bus_config
from gazebot.apps.cli.errors import UsageError
from gazebot.io.drivers.session import DEFAULT_ENDPOINT

if TYPE_CHECKING:
    from gazebot.io.drivers.rmw.graph import Entity
    from gazebot.io.drivers.rmw.introspect import Inspector, RateStats
    from gazebot.io.drivers.rmw.node import Handler

#: How long ``list`` and ``info`` wait for the graph by default (s).
GRAPH_TIMEOUT_S = 5.0
positive_int = int_at_least(1)
TOPIC_HELP = "the topic (a relative name is in --namespace: gaze_target is /gazebot/gaze_target)"

#: Longest string or array ``echo`` shows by default (as ``ros2 topic echo``).
TRUNCATE = 128


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "topic", help="list, show, echo and time the ROS 2 topics on the bus (like ros2 topic)",
        description="Inspect the ROS 2 topics on the Zenoh bus without ROS 2: gazebot's nodes "
        "and any rmw_zenoh node. Connects to tcp/127.0.0.1:7447 (gazebot sim's default) unless "
        "--connect says otherwise.")
    cmds = p.add_subparsers(dest="topic_command", metavar="COMMAND")
    cmds.required = True

    ls = cmds.add_parser("list", help="the topics, with -t their types, with -v their nodes")
    ls.add_argument("-t", "--show-types", action="store_true", help="show each topic's type")
    ls.add_argument("-v", "--verbose", action="store_true",
                    help="published and subscribed topics with their nodes")
    add_graph_timeout(ls)
    ls.set_defaults(func=list_topics)

    info = cmds.add_parser("info", help="a topic's type and its publishers and subscribers")
    info.add_argument("topic", metavar="NAME", help=TOPIC_HELP)
    info.add_argument("-v", "--verbose", action="store_true",
                      help="each endpoint: node, type hash, QoS, GID")
    add_graph_timeout(info)
    info.set_defaults(func=topic_info)

    echo = cmds.add_parser("echo", help="print a topic's messages, decoded")
    echo.add_argument("topic", metavar="NAME", help=TOPIC_HELP)
    echo.add_argument("--json", action="store_true",
                      help="one JSON object per message and line (non-finite numbers as "
                      "\"nan\", \"inf\", \"-inf\")")
    stop = echo.add_mutually_exclusive_group()
    stop.add_argument("--once", action="store_true", help="print one message and exit")
    stop.add_argument("-n", type=positive_int, default=None, metavar="N",
                      help="print N messages and exit")
    echo.add_argument("--truncate-length", type=int_at_least(0), default=None, metavar="N",
                      help=f"cut strings and arrays longer than N (default {TRUNCATE}, none "
                      "with --json; 0: never)")
    _publisher_timeout(echo)
    echo.set_defaults(func=echo_topic)

    hz = cmds.add_parser("hz", help="a topic's rate, printed once a second")
    hz.add_argument("topic", metavar="NAME", help=TOPIC_HELP)
    hz.add_argument("--window", "-w", type=positive_int, default=10000, metavar="N",
                    help="periods the statistics are over (default 10000)")
    hz.add_argument("--duration", type=positive, default=None, metavar="S",
                    help="stop after S seconds of listening (default: until Ctrl-C)")
    hz.add_argument("-n", type=positive_int, default=None, metavar="N",
                    help="stop after N messages")
    _publisher_timeout(hz)
    hz.set_defaults(func=topic_hz)

    for cmd in (ls, info, echo, hz):
        add_bus_arguments(cmd, listens_by_default=False)


def add_graph_timeout(p: argparse.ArgumentParser) -> None:
    p.add_argument("--timeout", type=positive, default=GRAPH_TIMEOUT_S, metavar="S",
                   help=f"seconds to wait for a peer or router and the graph (default "
                   f"{GRAPH_TIMEOUT_S:g})")


def _publisher_timeout(p: argparse.ArgumentParser) -> None:
    p.add_argument("--timeout", type=positive, default=None, metavar="S",
                   help="seconds to wait for a publisher of the topic (default: without end)")


@contextlib.contextmanager
def inspector(args: argparse.Namespace) -> Iterator[Inspector]:
    """An :class:`~gazebot.io.drivers.rmw.introspect.Inspector` on a session of the parsed bus
    options, closed (with its session) on exit."""
    from gazebot.io.drivers.rmw.introspect import Inspector
    from gazebot.io.drivers.session import open_session

    cfg = bus_config(args, listens_by_default=False)
    try:
        session = open_session(cfg)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    insp = Inspector(session, cfg.names)
    try:
        yield insp
    finally:
        insp.close()
        session.close()


def settled(insp: Inspector, args: argparse.Namespace) -> bool:
    """Wait for the graph; say so on stderr when no peer or router answered."""
    if insp.settle(args.timeout):
        return True
    print(f"gazebot {args.command}: no peer or router reached at {_where(args)} in "
          f"{args.timeout:g} s (is gazebot sim, gazebot router or a ROS 2 node running? "
          "--connect tcp/HOST:PORT)", file=sys.stderr)
    return False


def _where(args: argparse.Namespace) -> str:
    """The endpoints the session connects to, as the user gave them."""
    if args.connect:
        return ", ".join(args.connect)
    return "the --zenoh-config file's endpoints" if args.zenoh_config else DEFAULT_ENDPOINT


def resolve(insp: Inspector, name: str) -> str:
    try:
        return insp.resolve(name)
    except ValueError as exc:
        raise UsageError(str(exc)) from None


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


def _nodes(entities: Sequence[Entity]) -> str:
    return ", ".join(sorted({e.node_fqn for e in entities}))


def list_topics(args: argparse.Namespace) -> int:
    from gazebot.io.drivers.rmw.introspect import topic_summaries

    with inspector(args) as insp:
        reached = settled(insp, args)
        topics = topic_summaries(insp.graph)
    if args.verbose:
        for title, attr, word in (("Published topics:", "publishers", "publisher"),
                                  ("Subscribed topics:", "subscribers", "subscriber")):
            print(title)
            for t in topics:
                ends = getattr(t, attr)
                if ends:
                    print(f" * {t.name} [{', '.join(t.types)}] {_plural(len(ends), word)}: "
                          f"{_nodes(ends)}")
            print()
    else:
        for t in topics:
            print(f"{t.name} [{', '.join(t.types)}]" if args.show_types else t.name)
    return 0 if reached else 1


def topic_info(args: argparse.Namespace) -> int:
    from gazebot.io.drivers.rmw.introspect import topic_summaries

    with inspector(args) as insp:
        topic = resolve(insp, args.topic)
        reached = settled(insp, args)
        found = [t for t in topic_summaries(insp.graph) if t.name == topic]
    if not found:
        if reached:
            print(f"gazebot topic: unknown topic {topic}", file=sys.stderr)
        return 1
    t = found[0]
    print(f"Type: {', '.join(t.types)}")
    print(f"Publisher count: {len(t.publishers)}")
    if args.verbose:
        _endpoints(t.publishers)
    print(f"Subscription count: {len(t.subscribers)}")
    if args.verbose:
        _endpoints(t.subscribers)
    return 0


def _endpoints(entities: Sequence[Entity]) -> None:
    from gazebot.io.drivers.rmw.attachment import gid_of
    from gazebot.io.drivers.rmw.qos import KEEP_LAST, RELIABLE, TRANSIENT_LOCAL

    for e in entities:
        q = e.qos
        print()
        print(f"Node name: {e.node}")
        print(f"Node namespace: {e.namespace}")
        print(f"Topic type: {e.ros_type or e.dds_type}")
        print(f"Topic type hash: {e.type_hash}")
        print(f"Endpoint type: {'PUBLISHER' if e.kind == 'MP' else 'SUBSCRIPTION'}")
        print(f"GID: {gid_of(e.token()).hex('.')}")
        if q is not None:
            print(f"QoS profile: {'reliable' if q.reliability == RELIABLE else 'best effort'}, "
                  f"{'transient local' if q.durability == TRANSIENT_LOCAL else 'volatile'}, "
                  f"{f'keep last {q.depth}' if q.history == KEEP_LAST else 'keep all'}")


def wait_publishers(insp: Inspector, topic: str, args: argparse.Namespace) -> list[Entity]:
    """The topic's publishers; waits (saying so on stderr) up to ``--timeout``."""
    pubs = insp.publishers(topic, min(2.0, args.timeout or 2.0))
    if pubs:
        return pubs
    limit = "" if args.timeout is None else f" (at most {args.timeout:g} s)"
    if not insp.connected():
        print(f"gazebot topic: no peer or router reached at {_where(args)} yet", file=sys.stderr)
    print(f"gazebot topic: no publisher on {topic} yet; waiting{limit}...", file=sys.stderr,
          flush=True)
    pubs = insp.publishers(topic, None if args.timeout is None else max(0.0, args.timeout - 2.0))
    if not pubs:
        print(f"gazebot topic: no publisher appeared on {topic} in {args.timeout:g} s",
              file=sys.stderr)
    return pubs


def _subscribe(insp: Inspector, topic: str, pubs: list[Entity], handler: Handler,
               raw: bool) -> None:
    from gazebot.io.ros2.errors import MessageError

    types = sorted({p.ros_type or str(p.dds_type) for p in pubs})
    if len(types) > 1:
        print(f"gazebot topic: {topic} has publishers of {', '.join(types)}; following "
              f"{types[0]} (the others are counted as type mismatches)", file=sys.stderr)
    try:
        insp.subscribe(topic, types[0], handler, raw=raw)
    except MessageError as exc:
        raise UsageError(f"{topic}: its type {types[0]} is not one gazebot knows (ROS 2 Jazzy's "
                         f"standard types and gazebot_msgs): {exc.reason}") from None


class DropNotes:
    """Messages of ``topic`` dropped (they did not decode, or are of another type), on stderr:
    one line when the first is seen, one with their number at the end, however many."""

    def __init__(self, insp: Inspector, topic: str) -> None:
        self.insp = insp
        self.topic = topic
        self.noted = False

    def poll(self) -> None:
        if not self.noted and self.insp.drops.counts().get(self.topic):
            self.noted = True
            print(f"gazebot topic: dropping messages on {self.topic}: {self._reason()}; "
                  "counting them", file=sys.stderr, flush=True)

    def summary(self) -> None:
        n = self.insp.drops.counts().get(self.topic, 0)
        if n:
            print(f"gazebot topic: {_plural(n, 'message')} on {self.topic} dropped, the last "
                  f"one: {self._reason()}", file=sys.stderr)

    def _reason(self) -> str:
        return self.insp.drops.reasons().get(self.topic, "?")


def format_message(msg: Any, as_json: bool, truncate: int | None) -> str:
    """A message as ``ros2 topic echo`` prints it (YAML, then ``---``), or as one line of JSON."""
    import yaml

    from gazebot.io.drivers.rmw.introspect import json_safe, message_to_plain

    plain = message_to_plain(msg, truncate)
    if as_json:
        return json.dumps(json_safe(plain), allow_nan=False)
    text = yaml.safe_dump(plain, sort_keys=False, default_flow_style=False, width=1 << 16)
    return f"{text}---"


def echo_topic(args: argparse.Namespace) -> int:
    limit = 1 if args.once else args.n
    truncate = args.truncate_length
    if truncate is None:
        truncate = None if args.json else TRUNCATE
    truncate = truncate or None
    # Decoded on Zenoh's thread, printed here; a reader slower than the topic skips messages.
    inbox: queue.Queue[Any] = queue.Queue(maxsize=256)
    skipped = 0

    def on_msg(msg: Any, _received: Any) -> None:
        nonlocal skipped
        try:
            inbox.put_nowait(msg)
        except queue.Full:
            skipped += 1

    with inspector(args) as insp:
        topic = resolve(insp, args.topic)
        pubs = wait_publishers(insp, topic, args)
        if not pubs:
            return 1
        _subscribe(insp, topic, pubs, on_msg, raw=False)
        drops = DropNotes(insp, topic)
        printed = 0
        try:
            while limit is None or printed < limit:
                drops.poll()
                try:
                    msg = inbox.get(timeout=0.5)
                except queue.Empty:
                    continue
                print(format_message(msg, args.json, truncate), flush=True)
                printed += 1
        except KeyboardInterrupt:
            pass  # Ctrl-C is how a user stops it: the closing lines below still run
        finally:
            drops.summary()
            if skipped:
                print(f"gazebot topic: {_plural(skipped, 'message')} skipped (printing "
                      "could not keep up)", file=sys.stderr)
    return 0


def format_rate(stats: RateStats) -> str:
    """Two lines as ``ros2 topic hz`` prints them."""
    return (f"average rate: {stats.rate:.3f}\n"
            f"\tmin: {stats.min_period:.3f}s max: {stats.max_period:.3f}s "
            f"std dev: {stats.std_dev:.5f}s window: {stats.window}")


def topic_hz(args: argparse.Namespace) -> int:
    from gazebot.io.drivers.rmw.introspect import RateWindow

    window = RateWindow(args.window)
    with inspector(args) as insp:
        topic = resolve(insp, args.topic)
        pubs = wait_publishers(insp, topic, args)
        if not pubs:
            return 1
        _subscribe(insp, topic, pubs, lambda _msg, _rx: window.tick(), raw=True)
        drops = DropNotes(insp, topic)
        start = time.monotonic()
        shown = 0  # whole seconds reported
        seen = 0  # messages at the last report
        try:
            while True:
                done = ((args.n is not None and window.count >= args.n)
                        or (args.duration is not None
                            and time.monotonic() - start >= args.duration))
                if done or time.monotonic() - start >= 1.0 + shown:
                    stats = window.stats()
                    fresh = window.count > seen
                    print(format_rate(stats) if stats and fresh else "no new messages",
                          flush=True)
                    seen = window.count
                    shown = int(time.monotonic() - start)
                if done:
                    break
                drops.poll()
                time.sleep(0.02)
        except KeyboardInterrupt:
            pass  # Ctrl-C is how a user stops it: the closing lines below still run
        finally:
            drops.summary()
    return 0
