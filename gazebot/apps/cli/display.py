"""``gazebot display``: the program for the robot's head screen. It subscribes to the engine's eye
state on the Zenoh bus and draws the robot's eyes locally at the screen's refresh rate."""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

from gazebot.apps.cli.argtypes import positive, seed_value
from gazebot.apps.cli.bus import add_bus_arguments, bus_config
from gazebot.apps.cli.choices import add_robot_argument
from gazebot.apps.cli.errors import UsageError
from gazebot.io.ros2 import topics


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "display",
        help="show the robot's eyes on its head screen, driven by the engine over the bus",
        description="Subscribe to the engine's eyes/state (yaw, pitch, blink, distance) and "
        "draw the robot's eyes at the screen rate; between updates the eyes drift slightly; "
        "when the engine goes silent they return to a neutral pose, blink on their own and the "
        "status line says so. Headless with SDL_VIDEODRIVER=dummy (e.g. with --record).",
    )
    add_robot_argument(p)
    p.add_argument("--style", default=None, help="eye style name or YAML (default: the robot's)")
    p.add_argument("--fullscreen", action="store_true", help="fill the monitor")
    p.add_argument("--fps", type=positive, default=None,
                   help="screen refresh rate, frames/s (default 60; with --record: 30)")
    p.add_argument("--record", type=Path, default=None, metavar="FILE.mp4",
                   help="also record what the screen shows (H.264 MP4, real time)")
    p.add_argument("--duration", type=positive, default=None, metavar="S",
                   help="seconds to run (default: until the window closes or Ctrl-C)")
    p.add_argument("--silent-after", type=positive, default=0.5, metavar="S",
                   help="s without eye state before the engine counts as silent (default 0.5)")
    p.add_argument("--no-status", action="store_true", help="no status line on the screen")
    p.add_argument(
        "--seed", type=seed_value, default=0, help="seed of the eyes' own motion and blinks"
    )
    p.add_argument("--json", action="store_true", help="print a JSON summary at the end")
    add_bus_arguments(p, listens_by_default=False)
    p.set_defaults(func=handle)


def handle(args: argparse.Namespace) -> int:
    from gazebot.apps.render import EyeRenderer
    from gazebot.apps.render.head_display import EyeAnimator, EyeAnimatorConfig, HeadScreen
    from gazebot.apps.render.video import open_h264_writer
    from gazebot.io.drivers.zenoh_display import ZenohDisplayNode

    if args.record is not None and args.record.suffix.lower() != ".mp4":
        raise UsageError(f"--record must name an .mp4 file, got {args.record}")
    fps = args.fps or (30.0 if args.record is not None else 60.0)
    renderer = EyeRenderer.for_robot(args.robot, style=args.style)
    cfg = bus_config(args, listens_by_default=False)
    animator = EyeAnimator(EyeAnimatorConfig(silent_after=args.silent_after), seed=args.seed)
    node = ZenohDisplayNode.open(cfg)
    screen = writer = None
    summary: dict[str, Any] = {}
    try:
        screen = HeadScreen(renderer, fullscreen=args.fullscreen, status_bar=not args.no_status,
                            caption=f"gazebot display: {renderer.style.name}")
        if args.record is not None:
            writer = open_h264_writer(args.record, fps, screen.size)
        print(f"gazebot display: {args.robot} eyes from {cfg.names.resolve(topics.EYES.name)} "
              f"(connect {list(cfg.connect)}) at {fps:g} frames/s", file=sys.stderr)
        summary = run_display(node, screen, animator, fps, args.duration, writer,
                              key=cfg.names.resolve(topics.EYES.name), robot=args.robot)
        if writer is not None:
            writer.close()
            summary["video"] = str(args.record)
    except BaseException:
        if writer is not None:
            writer.abort()
        raise
    finally:
        if screen is not None:
            screen.close()
        node.close()
    print(json.dumps(summary) if args.json else "\n".join(f"{k}: {v}" for k, v in summary.items()))
    return 0


def run_display(
    node: Any,
    screen: Any,
    animator: Any,
    fps: float,
    duration: float | None,
    writer: Any = None,
    key: str = "",
    robot: str = "",
    clock: Any = time.monotonic,
) -> dict[str, Any]:
    """The display loop: at each of the ``fps`` slots per second, show the animator's pose for
    the newest eye state; the video (``writer``) gets one frame per slot, so it plays in real
    time (a slot the loop missed repeats the previous image, counted in ``repeated_frames``).
    Returns the summary."""
    from gazebot.apps.render.head_display import status_text

    period = 1.0 / fps
    start = clock()
    end = math.inf if duration is None else start + duration
    drawn = repeated = slots = 0
    states = {"live": 0, "silent": 0, "waiting": 0}
    last_beat = -math.inf
    try:
        while True:
            now = clock()
            if now >= end or screen.closed():
                break
            msg, age = node.latest()
            pose = animator.update(now - start, msg, age)
            states[pose.state] += 1
            screen.show(pose, status_text(robot, key, pose, age))
            drawn += 1
            due = int((now - start) / period) + 1  # video slots begun by now
            if writer is not None and due > slots:
                # This image fills the slots since the last one (more than one: the loop was
                # late, and the video stays in real time).
                image = screen.image()
                for _ in range(due - slots):
                    writer.append(image)
                repeated += due - slots - 1
                slots = due
            if now - last_beat >= 0.5:
                last_beat = now
                node.status(pose.state, {"frames": drawn, "received": node.received})
            delay = start + due * period - clock()
            if delay > 0:
                time.sleep(delay)
    except KeyboardInterrupt:
        pass  # Ctrl-C is how a display without --duration is stopped: not an error
    if writer is not None and duration is not None and slots and now >= end:
        # Ended by --duration: the video is exactly that long. The last slots may have begun
        # while the loop was late (a busy machine); they repeat the last image like any other
        # missed slot, so the recording keeps its length whatever the load.
        total = math.ceil(duration / period - 1e-9)
        if total > slots:
            image = screen.image()
            for _ in range(total - slots):
                writer.append(image)
            repeated += total - slots
            slots = total
    elapsed = max(clock() - start, 1e-9)
    return {
        "frames": drawn,
        "fps": round(drawn / elapsed, 1),
        "seconds": round(elapsed, 2),
        "eye_states_received": node.received,
        "live_frames": states["live"],
        "silent_frames": states["silent"] + states["waiting"],
        "video_frames": slots if writer is not None else 0,
        "repeated_frames": repeated,
    }
