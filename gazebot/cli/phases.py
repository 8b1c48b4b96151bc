"""``gazebot phases FILE.csv [--online] [--json] [--config FILE]``: segment a trajectory CSV."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import TYPE_CHECKING

from gazebot.cli.errors import UsageError

if TYPE_CHECKING:
    from gazebot.phases import Segment


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "phases",
        help="split a hand-trajectory CSV into reach, transfer and retreat",
        description=(
            "Segment a trajectory CSV (header t,giver_hand_x..z,receiver_hand_x..z"
            "[,giver_face_x..z][,gripper_closed][,load_share]; s and m; empty cell = missing) "
            "into handover phases. "
            "Offline by default (whole recording, the seed's transfer rule); --online replays it "
            "through the causal detector the engine runs."
        ),
    )
    p.add_argument("file", metavar="FILE.csv", help="trajectory CSV")
    p.add_argument("--online", action="store_true", help="replay through the online detector")
    p.add_argument("--json", action="store_true", help="print one JSON document on stdout")
    p.add_argument(
        "--config", default=None, help="phase thresholds YAML (default: configs/phases.yaml)"
    )
    p.set_defaults(func=handle)


def _fmt(x: float | None) -> str:
    return "-" if x is None or not math.isfinite(x) else f"{x:8.3f}"


def handle(args: argparse.Namespace) -> int:
    from gazebot.phases import load_phase_config, load_trajectory_csv, run_online, segment

    config = load_phase_config(args.config)
    try:
        traj = load_trajectory_csv(args.file)
    except UnicodeDecodeError as exc:
        # The bare codec message names neither the file nor what to do about it.
        raise UsageError(
            f"{args.file}: not UTF-8 text (byte {exc.object[exc.start]:#04x} at offset "
            f"{exc.start}); save the CSV as UTF-8"
        ) from None
    _, reordered, dropped = traj.cleaned()
    if reordered or dropped:
        print(
            f"gazebot phases: warning: {args.file}: {reordered} sample(s) out of time order, "
            f"{dropped} dropped (duplicate or missing time)",
            file=sys.stderr,
        )
    segments: list[Segment]
    if args.online:
        result = run_online(traj, config)
        segments = result.segments
    else:
        segments = segment(traj, config)
    if args.json:
        json.dump([s.to_json() for s in segments], sys.stdout, indent=1)
        sys.stdout.write("\n")
        return 0
    if not segments:
        print("no handover found")
        return 0
    head = f"{'handover':>8}  {'phase':<9}{'start':>8}  {'end':>8}  {'duration':>8}"
    if args.online:
        head += f"  {'detected':>8}"
    print(head)
    t_end = float(traj.t[-1]) if len(traj) else float("nan")
    for s in segments:
        line = (
            f"{s.handover:>8}  {s.phase.value:<9}{_fmt(s.start)}  {_fmt(s.end)}  {_fmt(s.duration)}"
        )
        if args.online:
            line += f"  {_fmt(s.detected_at)}"
        if s.end >= t_end:
            line += "  (to end of data)"  # the recording stops inside this phase
        print(line)
    return 0
