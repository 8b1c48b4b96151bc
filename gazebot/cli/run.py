"""``gazebot run``: the gaze engine node alone, driving any robot that speaks gazebot's keys on
the Zenoh bus (the simulator of ``gazebot sim`` or a real robot's bridge)."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from gazebot.cli.sim import add_bus_arguments, bus_config, positive


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run",
        help="run the gaze engine node against a robot on the Zenoh bus",
        description="Subscribe to a robot's tracking, run the gaze engine and publish head "
        "commands, eye state (rendered eye frames while someone subscribes), events and a "
        "heartbeat.",
    )
    p.add_argument("--robot", default="sawyer", help="sawyer or jaco2 (or a robot YAML file)")
    p.add_argument("--behavior", default="face-hand-face", help="behavior name or YAML file")
    p.add_argument(
        "--gaze-mode",
        default=None,
        help="how the robot points its gaze: head-and-eyes, head-only "
        "(fixed display eyes) or eyes-only (head held still); default: the robot YAML",
    )
    p.add_argument("--phases", default=None, help="phase config YAML (default configs/phases.yaml)")
    p.add_argument("--seed", type=int, default=0, help="seed of behavior timings and blinks")
    p.add_argument("--duration", type=positive, default=None,
                   help="seconds to run (default: until Ctrl-C)")
    p.add_argument("--hold-timeout", type=positive, default=0.25,
                   help="s without tracking before holding the gaze (default 0.25)")
    p.add_argument("--face-timeout", type=positive, default=1.0,
                   help="s without tracking before looking at the last face (default 1.0)")
    p.add_argument("--no-robot-warning", type=positive, default=3.0, metavar="S",
                   help="warn on stderr if no robot data arrived after S seconds (default 3)")
    p.add_argument("--no-resync", action="store_true",
                   help="do not catch up with a handover under way at start")
    p.add_argument("--no-eye-frames", action="store_true",
                   help="never render eye frames (eye state is always published)")
    p.add_argument("--json", action="store_true", help="print a JSON summary at the end")
    add_bus_arguments(p, listens_by_default=False)
    p.set_defaults(func=handle)


class LazyEyeRenderer:
    """Builds the robot's eye renderer on first use (only when someone wants frames)."""

    def __init__(self, robot: str) -> None:
        self.robot = robot
        self._renderer: Any = None

    def render(
        self, yaw: float, pitch: float, blink: float = 0.0, distance: float | None = None
    ) -> Any:
        if self._renderer is None:
            from gazebot.render import EyeRenderer

            self._renderer = EyeRenderer.for_robot(self.robot)
        return self._renderer.render(yaw, pitch, blink=blink, distance=distance)


def build_engine_node(
    robot: str,
    behavior: str,
    driver: Any,
    seed: int = 0,
    phases: str | None = None,
    config: Any = None,
    eye_frames: bool = True,
    engine: Any = None,
    warn: Any = None,
) -> Any:
    """A :class:`~gazebot.drivers.engine_node.EngineNode` running ``engine`` (default:
    ``GazeEngine.from_config(robot, behavior, phases, seed=seed)``), with blinks and lazily
    rendered eye frames; ``warn(text)`` receives operator warnings (no robot seen)."""
    from gazebot.drivers.engine_node import EngineNode
    from gazebot.engine import GazeEngine

    if engine is None:
        engine = GazeEngine.from_config(robot=robot, behavior=behavior, phases=phases, seed=seed)
    try:
        from gazebot.render import BlinkModel

        blink = BlinkModel(seed)
    except ImportError:  # eyes package absent: the eyes never blink
        blink = None
    renderer = LazyEyeRenderer(engine.robot.name) if eye_frames else None
    return EngineNode(engine, driver, config, blink=blink, eye_renderer=renderer, warn=warn)


def handle(args: argparse.Namespace) -> int:
    from gazebot.drivers.engine_node import EngineNodeConfig
    from gazebot.drivers.zenoh_driver import ZenohRobotDriver

    if args.face_timeout < args.hold_timeout:
        raise ValueError("--face-timeout must be >= --hold-timeout")
    cfg = bus_config(args, listens_by_default=False)
    node_cfg = EngineNodeConfig(
        hold_timeout=args.hold_timeout,
        face_timeout=args.face_timeout,
        resync=not args.no_resync,
        no_robot_warning=args.no_robot_warning,
    )
    from gazebot.engine import GazeEngine

    # Build the engine before joining the bus: samples arriving meanwhile would only go stale.
    from gazebot.kinematics.config import with_gaze_mode

    robot = with_gaze_mode(args.robot, args.gaze_mode)
    engine = GazeEngine.from_config(robot, args.behavior, args.phases, seed=args.seed)
    driver = ZenohRobotDriver.open(cfg, "engine")
    try:
        endpoints = f"listen {list(cfg.listen)}, connect {list(cfg.connect)}"

        def warn(text: str) -> None:
            print(f"gazebot run: warning: {text} ({endpoints})", file=sys.stderr, flush=True)

        node = build_engine_node(args.robot, args.behavior, driver, seed=args.seed,
                                 config=node_cfg, eye_frames=not args.no_eye_frames,
                                 engine=engine, warn=warn)
        print(
            f"gazebot run: {args.behavior} on {node.engine.robot.name} at gazebot/{cfg.robot_id}/ "
            f"({endpoints})",
            file=sys.stderr,
        )
        try:
            node.run(duration=args.duration)
        except KeyboardInterrupt:
            pass
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
        }
    finally:
        driver.close()
    print(json.dumps(summary) if args.json else "\n".join(f"{k}: {v}" for k, v in summary.items()))
    return 0
