"""``gazebot phases FILE [--method M] [--online] [--json] [--config FILE] [--giver-hand NAME]
[--receiver-hand NAME] [--giver-face NAME] [--unit U] [--rate HZ] [--max-gap S]
[--workspace M]``: segment a recording."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import TYPE_CHECKING

from gazebot.apps.cli.argtypes import positive
from gazebot.core.phases.trajectory import POINTS

if TYPE_CHECKING:
    from gazebot.core.phases import Segment


def add_recording_options(p: argparse.ArgumentParser, prefix: str = "") -> None:
    """The point-name, unit and rate options of a recording (shared with ``--giver-motion``)."""
    p.add_argument(
        f"--{prefix}giver-hand",
        default=None,
        metavar="NAME",
        help="point/label/topic/frame of the giver's hand (default: giver_hand in CSV)",
    )
    p.add_argument(
        f"--{prefix}receiver-hand",
        default=None,
        metavar="NAME",
        help="point of the receiver's hand (default: receiver_hand in CSV)",
    )
    p.add_argument(
        f"--{prefix}giver-face",
        default=None,
        metavar="NAME",
        help="point of the giver's face (optional)",
    )
    p.add_argument(
        f"--{prefix}unit",
        default=None,
        choices=None,
        metavar="UNIT",
        help="length unit of CSV / pose-folder coordinates: m (default), cm or mm",
    )
    p.add_argument(
        f"--{prefix}rate",
        default=None,
        type=positive,
        metavar="HZ",
        help="sampling rate of a pose folder (its files have no time column)",
    )


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "phases",
        help="split a hand-motion recording into reach, transfer and retreat",
        description=(
            "Segment a recording into handover phases. Formats: CSV (t + NAME_x,NAME_y,NAME_z "
            "columns; s and m unless --unit; empty/NaN = missing), C3D (labels; its own unit), "
            "ROS 1/2 bags and MCAP files (PoseStamped, PointStamped, TransformStamped topics, "
            "/tf child frames; gazebot's own tracking topics by default), a folder of per-body "
            "pose CSVs (--rate). Offline by default (whole "
            "recording); --online replays it through the causal detector the engine runs."
        ),
    )
    from gazebot.core.phases.methods import PHASE_METHODS

    p.add_argument(
        "file", metavar="FILE", help="recording: .csv, .c3d, .mcap, .bag, ROS 2 bag, folder"
    )
    p.add_argument(
        "--method",
        default=None,
        choices=PHASE_METHODS.names(),
        help="phase rules (default: method in the config, gazebot)",
    )
    p.add_argument("--online", action="store_true", help="replay through the online detector")
    p.add_argument("--json", action="store_true", help="print one JSON document on stdout")
    p.add_argument(
        "--config", default=None, help="phase settings YAML (default: configs/phases.yaml)"
    )
    add_recording_options(p)
    p.add_argument(
        "--max-gap",
        type=float,
        default=None,
        metavar="S",
        help="largest time step between two samples, s (default: 60); a larger gap is an error "
        "naming the line",
    )
    p.add_argument(
        "--workspace",
        type=float,
        default=None,
        metavar="M",
        help="largest plausible coordinate magnitude, m (default: 50); a point beyond it is a "
        "missing sample, counted",
    )
    p.set_defaults(func=handle)


# Rules that split one recorded handover after the fact: online they see every pause as a
# handover (4.4.3) or a transfer from the first stop (7.2.5).
OFFLINE_METHODS = {
    "seed-4.4.3": "the seed's split of single giving motions (4.4.3)",
    "seed-7.2.5": "the seed's annotation rule (7.2.5)",
}


def _limits(args: argparse.Namespace):
    from gazebot.apps.cli.errors import UsageError
    from gazebot.io.recordings import RecordingLimits

    kw = {}
    for option, field in (("max_gap", "max_gap_s"), ("workspace", "workspace_m")):
        value = getattr(args, option)
        if value is not None:
            if not (math.isfinite(value) and value > 0):
                flag = "--" + option.replace("_", "-")
                raise UsageError(f"{flag} must be a finite number > 0, got {value}")
            kw[field] = value
    return RecordingLimits(**kw)


def _fmt(x: float | None) -> str:
    return "-" if x is None or not math.isfinite(x) else f"{x:8.3f}"


def handle(args: argparse.Namespace) -> int:
    from gazebot.core.phases import load_phase_config, run_online, segment
    from gazebot.io.recordings import PointNames, load_recording

    config = load_phase_config(args.config)
    if args.method is not None:
        config = config.model_copy(update={"method": args.method})
    names = PointNames(args.giver_hand, args.receiver_hand, args.giver_face)
    rec = load_recording(args.file, names, unit=args.unit, rate=args.rate, limits=_limits(args))
    if args.online and config.method in OFFLINE_METHODS:
        print(
            f"gazebot phases: warning: --method {config.method} is "
            f"{OFFLINE_METHODS[config.method]}, meant offline on a recording of one handover; "
            "online it may report spurious or early phases (use --method gazebot online)",
            file=sys.stderr,
        )
    if rec.out_of_workspace:
        print(
            f"gazebot phases: warning: {args.file}: {rec.out_of_workspace} point sample(s) "
            f"beyond the workspace bound made missing",
            file=sys.stderr,
        )
    traj = rec.trajectory
    for note in rec.notes:
        print(f"gazebot phases: warning: {rec.source}: {note}", file=sys.stderr)
    _, reordered, dropped = traj.cleaned()
    if reordered or dropped:
        print(
            f"gazebot phases: warning: {args.file}: {reordered} sample(s) out of time order, "
            f"{dropped} dropped (duplicate or missing time)",
            file=sys.stderr,
        )
    segments: list[Segment]
    if args.online:
        segments = run_online(traj, config).segments
    else:
        segments = segment(traj, config)
    if args.json:
        doc = {
            "source": rec.source,
            "format": rec.format,
            "method": config.method,
            "online": bool(args.online),
            "units": {"time": "s", "length": "m", "file_length": rec.unit},
            "rate_hz": None if math.isnan(rec.rate) else round(rec.rate, 3),
            "names": dict(
                zip(POINTS, rec.names, strict=True)
            ),
            "segments": [s.to_json() for s in segments],
        }
        json.dump(doc, sys.stdout, indent=1)
        sys.stdout.write("\n")
        return 0
    print(f"# {rec.describe()}; method {config.method}{' (online)' if args.online else ''}")
    head = f"{'handover':>8}  {'phase':<9}{'start':>8}  {'end':>8}  {'duration':>8}"
    if args.online:
        head += f"  {'detected':>8}"
    print(head)
    if not segments:
        print("(no handover found)")
        return 0
    for s in segments:
        line = (
            f"{s.handover:>8}  {s.phase.value:<9}{_fmt(s.start)}  {_fmt(s.end)}  {_fmt(s.duration)}"
        )
        if args.online:
            line += f"  {_fmt(s.detected_at)}"
        if s.open:
            line += "  (to end of data)"
        print(line)
    return 0
