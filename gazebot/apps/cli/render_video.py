"""``gazebot render video``: an off-screen MuJoCo render of a full handover to an H.264 MP4,
deterministic for a seed. The observer camera stands in front of the robot, where its head
screen (the eyes) faces it, with a close-up of the screen in a corner (docs/observer-view.md)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from gazebot.apps.cli.argtypes import seed_value
from gazebot.apps.cli.choices import (
    add_behavior_argument,
    add_gaze_mode_argument,
    add_robot_argument,
    add_scene_argument,
)
from gazebot.apps.cli.errors import UsageError, robot_with_gaze_mode
from gazebot.apps.render.video_settings import VIDEO


def register(kinds: argparse._SubParsersAction) -> None:
    parser = kinds.add_parser(
        "video", help="render a simulated handover to an MP4", description=__doc__
    )
    add_robot_argument(parser)
    add_behavior_argument(parser, required=True)
    add_scene_argument(parser)
    add_gaze_mode_argument(parser)
    parser.add_argument("--out", type=Path, required=True, help="output FILE.mp4")
    parser.add_argument("--seed", type=seed_value, default=0, help="random seed (default: 0)")
    parser.add_argument("--width", type=int, default=VIDEO.width,
                        help=f"width, px, even (default: {VIDEO.width})")
    parser.add_argument("--height", type=int, default=VIDEO.height,
                        help=f"height, px, even (default: {VIDEO.height})")
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second (default: 30)")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    parser.add_argument(
        "--no-inset",
        action="store_true",
        help="no close-up of the robot's head screen in the video's corner (default: the scene's)",
    )
    from gazebot.apps.cli.demo import add_giver_motion_options

    add_giver_motion_options(parser)
    parser.set_defaults(func=run_render_video)


def run_render_video(args: argparse.Namespace) -> int:
    from gazebot.apps.cli.demo import giver_factory
    from gazebot.apps.render.gl_check import OffscreenRenderingError
    from gazebot.apps.sim.record import check_video_size, render_handover_video
    from gazebot.apps.sim.scene_config import with_inset

    if args.out.suffix.lower() != ".mp4":
        raise UsageError(f"--out must name an .mp4 file, got {args.out}")
    try:
        check_video_size(args.width, args.height, args.fps)
    except ValueError as exc:
        raise UsageError(f"--width/--height/--fps: {exc}") from None
    try:
        path = render_handover_video(
            robot_with_gaze_mode(args.robot, args.gaze_mode),
            args.behavior,
            with_inset(args.scene, False) if args.no_inset else args.scene,
            args.out,
            seed=args.seed,
            width=args.width,
            height=args.height,
            fps=args.fps,
            progress=not args.no_progress,
            giver_factory=giver_factory(args),
        )
    except OffscreenRenderingError as exc:
        print(f"gazebot: error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {path}")
    return 0
