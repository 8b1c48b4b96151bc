"""``gazebot render eyes``: draw the robot's eyes for one gaze (degrees here) into a PNG/JPEG."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from gazebot.apps.cli.choices import add_robot_argument
from gazebot.apps.cli.errors import UsageError
from gazebot.core.config import ConfigError


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "eyes",
        help="render the head-screen eyes for one eye yaw/pitch into an image",
        description=(
            "Render the eyes shown on the robot's head screen. Positive yaw = the robot looks to "
            "its left (pupils move right in the image); positive pitch = looking down."
        ),
    )
    add_robot_argument(parser)
    parser.add_argument(
        "--style", default=None, help="eye style name or YAML (default: the robot's)"
    )
    parser.add_argument(
        "--yaw", type=float, default=0.0, help="eye yaw, degrees (+ = robot's left)"
    )
    parser.add_argument("--pitch", type=float, default=0.0, help="eye pitch, degrees (+ = down)")
    parser.add_argument(
        "--blink", type=float, default=0.0, help="lid closure 0 (open) .. 1 (closed)"
    )
    parser.add_argument(
        "--distance", type=float, default=None, help="target distance, m (vergence)"
    )
    parser.add_argument("--width", type=int, default=None, help="image width, px (default: screen)")
    parser.add_argument(
        "--height", type=int, default=None, help="image height, px (default: screen)"
    )
    parser.add_argument("--out", default="eyes.png", help="output image (.png or .jpg)")
    parser.add_argument("--json", action="store_true", help="print a JSON summary to stdout")
    parser.set_defaults(func=handler)


def handler(args: argparse.Namespace) -> int:
    import cv2

    from gazebot.apps.render import EyeRenderer

    for name in ("yaw", "pitch", "blink"):
        if not math.isfinite(getattr(args, name)):
            raise UsageError(f"--{name} must be a finite number, got {getattr(args, name)}")
    if not 0.0 <= args.blink <= 1.0:
        raise UsageError(f"--blink must be in 0..1, got {args.blink}")
    out = Path(args.out)
    if out.suffix.lower() not in (".png", ".jpg", ".jpeg"):
        raise UsageError(f"--out must end in .png, .jpg or .jpeg, got {out}")
    try:
        renderer = EyeRenderer.for_robot(
            args.robot, width=args.width, height=args.height, style=args.style
        )
        img = renderer.render(
            math.radians(args.yaw), math.radians(args.pitch), blink=args.blink,
            distance=args.distance,
        )
    except ConfigError:
        raise
    except ValueError as exc:  # the renderer rejects the given size or distance
        raise UsageError(str(exc)) from None
    shown = _printable(out)
    if out.parent and not out.parent.is_dir():
        raise FileNotFoundError(f"output folder does not exist: {_printable(out.parent)}")
    # Encoded here and written by Python: cv2.imwrite takes the name as UTF-8 and crashes on
    # a file name that is not (bytes a shell passes through as they are).
    ok, data = cv2.imencode(out.suffix.lower(), img[..., ::-1])
    if not ok:
        raise UsageError(f"could not encode the image {shown}")
    out.write_bytes(data.tobytes())
    summary = {
        "out": shown,
        "robot": args.robot,
        "style": renderer.style.name,
        "width": renderer.width,
        "height": renderer.height,
        "yaw_deg": args.yaw,
        "pitch_deg": args.pitch,
        "blink": args.blink,
        "distance_m": args.distance,
    }
    print(
        json.dumps(summary) if args.json else f"wrote {shown} ({renderer.width}x{renderer.height})"
    )
    return 0


def _printable(path: Path) -> str:
    """``path`` as text a terminal can print: bytes that are not UTF-8 (kept by Python as
    surrogates) shown as ``\\udcXX`` escapes."""
    return str(path).encode("utf-8", "backslashreplace").decode("utf-8")
