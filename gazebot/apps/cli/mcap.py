"""``gazebot mcap recover FILE [--out FILE]``: rewrite an MCAP recording a killed recorder left
without its summary as a finished file every reader opens, as the MCAP CLI's ``mcap recover``
does (every complete chunk and message up to the first damaged record).

Also the ``--record-max-size`` / ``--record-max-duration`` options of ``gazebot run`` and
``gazebot sim`` (rosbag2's ``--max-bag-size`` / ``--max-bag-duration``)."""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING

from gazebot.apps.cli.argtypes import int_at_least, positive

if TYPE_CHECKING:
    from gazebot.io.ros2.mcap_writer import Split


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("mcap", help="repair MCAP recordings (like the mcap CLI)",
                       description="Work on MCAP recordings.")
    cmds = p.add_subparsers(dest="mcap_command", metavar="COMMAND")
    cmds.required = True
    rec = cmds.add_parser(
        "recover", help="rewrite a recording cut short (no summary) as a finished file",
        description="Copy every complete chunk and message of FILE (a recording whose process "
        "was killed, or damaged) into a new MCAP file with index and summary, as `mcap recover` "
        "does; reading stops at the first record that does not parse.")
    rec.add_argument("file", metavar="FILE", help="the MCAP file to recover")
    rec.add_argument("-o", "--out", metavar="FILE", default=None,
                     help="the recovered file (default: FILE's name with -recovered)")
    rec.add_argument("--json", action="store_true", help="print the result as JSON")
    rec.set_defaults(func=recover)


def recover(args: argparse.Namespace) -> int:
    from gazebot.io.recordings.mcap_recover import recover_mcap

    got = recover_mcap(args.file, args.out)
    if args.json:
        print(json.dumps({"file": str(got.path), "messages": got.messages, "chunks": got.chunks,
                          "last_log_time_ns": got.last_log_time_ns, "problem": got.problem}))
        return 0
    print(f"recovered {got.messages} messages from {got.chunks} chunks to {got.path}")
    if got.problem is not None:
        print(f"stopped at: {got.problem}")
    return 0


def add_record_split_arguments(parser: argparse.ArgumentParser) -> None:
    """``--record-max-size BYTES`` and ``--record-max-duration S`` (with ``--record``)."""
    parser.add_argument(
        "--record-max-size", metavar="BYTES", type=int_at_least(1), default=None,
        help="with --record: split the recording into NAME_0.mcap, NAME_1.mcap, ... of about "
        "this many bytes each (default: no limit), as ros2 bag record --max-bag-size")
    parser.add_argument(
        "--record-max-duration", metavar="S", type=positive, default=None,
        help="with --record: split the recording into files of this many seconds of log time "
        "each (default: no limit), as ros2 bag record --max-bag-duration")


def record_split(args: argparse.Namespace) -> Split | None:
    """The :class:`Split` of parsed :func:`add_record_split_arguments` options (``None``:
    one file)."""
    from gazebot.io.ros2.mcap_writer import Split

    if args.record_max_size is None and args.record_max_duration is None:
        return None
    return Split(args.record_max_size, args.record_max_duration)
