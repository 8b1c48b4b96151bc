"""``gazebot run``: the gaze engine node alone, driving any robot that speaks gazebot's ROS 2
topics on the Zenoh bus (the simulator of ``gazebot sim`` or a real robot's bridge)."""

from __future__ import annotations

import argparse
import contextlib
import json
import signal
import sys
import threading
from collections.abc import Iterator
from typing import TYPE_CHECKING

from gazebot.apps.cli.argtypes import positive, seed_value
from gazebot.apps.cli.bus import (
    add_bus_arguments,
    add_record_argument,
    bus_config,
    robot_base_frame,
)
from gazebot.apps.cli.choices import add_behavior_argument, add_robot_argument
from gazebot.apps.cli.errors import robot_with_gaze_mode
from gazebot.apps.cli.extras import extra_for
from gazebot.apps.cli.mcap import add_record_split_arguments, record_split
from gazebot.core.defaults import DEFAULT_BEHAVIOR
from gazebot.io.drivers.engine_node import EngineNodeConfig

if TYPE_CHECKING:
    from gazebot.apps.render.eyes import LazyEyeRenderer


class DeprecatedAlias(argparse.Action):
    """An option's old spelling: stores like the new one and warns once on stderr."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:  # type: ignore[no-untyped-def]
        new = "--" + self.dest.replace("_", "-")
        print(f"gazebot: {option_string} is deprecated, use {new} (the old name goes in the "
              "next release)", file=sys.stderr)
        setattr(namespace, self.dest, values)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run",
        help="run the gaze engine node against a robot on the Zenoh bus",
        description="Subscribe to a robot's tracking, run the gaze engine and publish head "
        "commands, eye state (rendered eye frames while someone subscribes), events and a "
        "heartbeat.",
    )
    add_robot_argument(p)
    add_behavior_argument(p, default=DEFAULT_BEHAVIOR)
    p.add_argument(
        "--gaze-mode",
        default=None,
        help="how the robot points its gaze: head-and-eyes, head-only "
        "(fixed display eyes) or eyes-only (head held still); default: the robot YAML",
    )
    p.add_argument("--phases", default=None, help="phase config YAML (default configs/phases.yaml)")
    p.add_argument("--seed", type=seed_value, default=0, help="seed of behavior timings and blinks")
    p.add_argument("--duration", type=positive, default=None,
                   help="seconds to run (default: until Ctrl-C)")
    node = EngineNodeConfig()  # the node's defaults are the options' defaults
    p.add_argument("--silent-after", type=positive, default=node.silence_after, metavar="S",
                   help="s without tracking before it counts as silent: the engine ticks "
                   "without samples, so the behavior's tracking-loss policy applies "
                   f"(default {node.silence_after:g})")
    # Deprecated spelling (one release): the same option as `gazebot display --silent-after`.
    p.add_argument("--silence-after", type=positive, dest="silent_after", metavar="S",
                   action=DeprecatedAlias, help=argparse.SUPPRESS)
    p.add_argument("--no-robot-warning", type=positive, default=node.no_robot_warning,
                   metavar="S", help="warn on stderr if no robot data arrived after S seconds "
                   f"(default {node.no_robot_warning:g})")
    p.add_argument("--no-resync", action="store_true",
                   help="do not catch up with a handover under way at start")
    p.add_argument("--standby", action="store_true",
                   help="if another engine already commands this robot, wait and take over "
                   "when it stops (default: exit with status 3)")
    p.add_argument("--no-eye-frames", action="store_true",
                   help="never render eye frames (eye state is always published)")
    p.add_argument("--json", action="store_true",
                   help="print a JSON summary at the end (also when stopped by Ctrl-C or "
                   "SIGTERM)")
    add_bus_arguments(p, listens_by_default=False)
    add_record_argument(p)
    add_record_split_arguments(p)
    p.set_defaults(func=handle)


def handle(args: argparse.Namespace) -> int:
    from gazebot.io.drivers.engine_node import EngineNode, EngineRefused
    from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver

    cfg = bus_config(args, listens_by_default=False, base_frame=robot_base_frame(args.robot))
    node_cfg = EngineNodeConfig(
        silence_after=args.silent_after,
        resync=not args.no_resync,
        no_robot_warning=args.no_robot_warning,
        standby=args.standby,
    )
    # Build the loop before joining the bus: samples arriving meanwhile would only go stale.
    from gazebot.core.runtime import GazeLoop

    robot = robot_with_gaze_mode(args.robot, args.gaze_mode)
    loop = GazeLoop.from_config(robot, args.behavior, args.phases, seed=args.seed)
    driver = ZenohRobotDriver.open(cfg, "engine")
    recorder = None
    try:
        if args.record:
            from gazebot.io.drivers.recorder import BusRecorder

            recorder = BusRecorder(driver.session, cfg.names, args.record,
                                   split=record_split(args))
        endpoints = f"listen {list(cfg.listen)}, connect {list(cfg.connect)}"

        def warn(text: str) -> None:
            print(f"gazebot run: warning: {text} ({endpoints})", file=sys.stderr, flush=True)

        eyes = None if args.no_eye_frames else _eye_renderer(loop.robot.name)
        node = EngineNode(loop, driver, node_cfg, warn=warn, eye_renderer=eyes)
        try:
            with _stop_on_sigterm() as stop:  # before saying it runs: SIGTERM from then on
                print(f"gazebot run: {args.behavior} on {node.engine.robot.name} under "
                      f"{cfg.names.namespace} ({endpoints})", file=sys.stderr, flush=True)
                node.run(duration=args.duration, stop=stop)
        except KeyboardInterrupt:
            pass  # Ctrl-C is how a user stops the node: the closing below runs as for SIGTERM
        except EngineRefused as exc:
            print(f"gazebot run: error: {exc}", file=sys.stderr, flush=True)
            return 3
        summary = {
            "frames": node.frames_processed,
            "commands": node.commands_sent,
            "phase": node.phase,
            "tracking": node.tracking,
            "peers": driver.peers(),
            "robot_seen": node.robot_seen,
            "warnings": node.warnings,
            "dropped": driver.dropped(),
            "tracking_skipped": driver.tracking_skipped,
            "type_mismatches": {k: str(v) for k, v in driver.type_mismatches().items()},
        }
        if recorder is not None:
            summary["recorded"] = {"file": str(recorder.close()), "messages": recorder.messages,
                                   "files": [str(f) for f in recorder.files]}
    finally:
        if recorder is not None:
            recorder.close()
        driver.close()
    print(json.dumps(summary) if args.json else "\n".join(f"{k}: {v}" for k, v in summary.items()))
    return 0


def _eye_renderer(robot: str) -> LazyEyeRenderer | None:
    """The robot's eye renderer, or ``None`` (a note on stderr) on an install without the
    ``render`` extra: the node then publishes eye state but no eye frames."""
    try:
        from gazebot.apps.render.eyes import LazyEyeRenderer
    except ModuleNotFoundError as exc:
        if extra_for(exc.name) != "render":
            raise
        print("gazebot run: note: no eye frames (they need the [render] extra); eye state is "
              "published", file=sys.stderr, flush=True)
        return None
    return LazyEyeRenderer(robot)


@contextlib.contextmanager
def _stop_on_sigterm() -> Iterator[threading.Event]:
    """An event SIGTERM sets while the block runs (as a process manager or launch file stops a
    node), so the run ends like Ctrl-C: shut down, then the summary. The previous handler is
    restored after; only the main thread can take signals (elsewhere: an event never set)."""
    stop = threading.Event()
    if threading.current_thread() is not threading.main_thread():
        yield stop
        return
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: stop.set())
    try:
        yield stop
    finally:
        signal.signal(signal.SIGTERM, previous)
