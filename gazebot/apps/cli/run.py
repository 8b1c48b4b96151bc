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
from gazebot.apps.cli.choices import (
    add_behavior_argument,
    add_gaze_mode_argument,
    add_robot_argument,
)
from gazebot.apps.cli.errors import robot_with_gaze_mode
from gazebot.apps.cli.extras import extra_for
from gazebot.apps.cli.mcap import add_record_split_arguments, record_split
from gazebot.core.defaults import DEFAULT_BEHAVIOR
from gazebot.io.drivers.engine_node import EngineNodeConfig

if TYPE_CHECKING:
    from gazebot.apps.render.eyes import LazyEyeRenderer
    from gazebot.core.runtime import GazeLoop
    from gazebot.io.drivers.rmw.node import RosNode

#: The topic ``--robot-description`` reads when given without one.
ROBOT_DESCRIPTION_TOPIC = "/robot_description"


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
    add_gaze_mode_argument(p)
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
    p.add_argument("--robot-description", nargs="?", const=ROBOT_DESCRIPTION_TOPIC,
                   default=None, metavar="TOPIC",
                   help="take the robot's URDF from its running stack (std_msgs/String, "
                   f"transient local; default topic {ROBOT_DESCRIPTION_TOPIC}); the robot YAML "
                   "then needs no urdf:/mjcf:, only what a URDF does not say")
    p.add_argument("--description-timeout", type=positive, default=10.0, metavar="S",
                   help="s to wait for the robot description (default 10)")
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
    from gazebot.core.runtime import GazeLoop
    from gazebot.io.drivers.tf_buffer import TfBuffer

    robot = robot_with_gaze_mode(args.robot, args.gaze_mode)
    # Tracking in any frame of /tf and /tf_static is transformed into the base frame.
    tf = TfBuffer()
    if args.robot_description is None:
        # Build the loop before joining the bus: samples arriving meanwhile would only go stale.
        loop = GazeLoop.from_config(robot, args.behavior, args.phases, seed=args.seed)
        driver = ZenohRobotDriver.open(cfg, "engine", tf=tf)
    else:
        driver = ZenohRobotDriver.open(cfg, "engine", tf=tf)
        try:
            stack_loop = _loop_from_stack(args, robot, driver.ros)
        except BaseException:
            driver.close()
            raise
        if stack_loop is None:
            driver.close()
            return 2
        loop = stack_loop
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
            "untransformed": dict(driver.untransformed),
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


def wait_robot_description(ros: RosNode, topic: str, timeout: float) -> str | None:
    """The URDF text the stack publishes on ``topic`` (``std_msgs/String``, transient local as
    ``robot_state_publisher`` latches it, so one published before this node started arrives
    too), or ``None`` when none came within ``timeout`` s."""
    from gazebot.io.drivers.rmw.qos import qos_of
    from gazebot.io.ros2 import topics

    got: list[str] = []
    arrived = threading.Event()

    def on(msg: object, received: object) -> None:
        if not arrived.is_set():
            got.append(str(getattr(msg, "data", "")))
            arrived.set()

    sub = ros.subscription(topic, topics.ROBOT_DESCRIPTION.type, on,
                           qos=qos_of("transient_local", 1))
    try:
        arrived.wait(timeout)
    finally:
        sub.undeclare()
    return got[0] if got else None


def _loop_from_stack(args: argparse.Namespace, robot: object, ros: RosNode) -> GazeLoop | None:
    """The gaze loop of the robot YAML ``robot`` with the URDF the stack publishes; ``None``
    (a message on stderr) when it does not come in time."""
    from gazebot.core.behaviors import load_behavior
    from gazebot.core.engine import GazeEngine
    from gazebot.core.kinematics.robot import RobotModel
    from gazebot.core.kinematics.robot_config import RobotConfig, load_robot_config
    from gazebot.core.phases import load_phase_config
    from gazebot.core.runtime import GazeLoop

    config = robot if isinstance(robot, RobotConfig) else load_robot_config(str(robot))[0]
    topic = ros.names.resolve(args.robot_description)
    print(f"gazebot run: waiting for the robot description on {topic} (at most "
          f"{args.description_timeout:g} s)", file=sys.stderr, flush=True)
    urdf = wait_robot_description(ros, args.robot_description, args.description_timeout)
    if urdf is None:
        print(f"gazebot run: error: no robot description on {topic} within "
              f"{args.description_timeout:g} s: is the stack's robot_state_publisher running "
              "on this bus (--connect, ROS_DOMAIN_ID)?", file=sys.stderr, flush=True)
        return None
    model = RobotModel.from_urdf_text(config, urdf, topic)
    engine = GazeEngine(model, load_behavior(args.behavior), load_phase_config(args.phases),
                        seed=args.seed)
    return GazeLoop(engine, seed=args.seed)


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
