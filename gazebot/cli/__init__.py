"""The ``gazebot`` command line: one module per command group, each with ``register(subparsers)``.

Angles on the command line are in degrees unless an option says otherwise; everything inside is SI.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from gazebot.cli.errors import UsageError
from gazebot.config import ConfigError
from gazebot.phases.trajectory import TrajectoryFormatError
from gazebot.recordings import RecordingError

# Command groups, in the order ``gazebot --help`` lists them.
COMMAND_MODULES = (
    "demo",
    "phases",
    "behaviors",
    "annotations",
    "ik",
    "render",
    "sim",
    "reach_plan",
    "run",
    "display",
    "study",
    "gps",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="gazebot",
        description="Robot gaze behavior engine for human-to-robot handovers.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMAND_MODULES:
        module = importlib.import_module(f"gazebot.cli.{name}")
        module.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        result = args.func(args)
        sys.stdout.flush()
    except BrokenPipeError:
        # The reader went away (e.g. `| head`): not an error of ours. Point stdout at devnull so
        # the interpreter's final flush does not complain again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except (ConfigError, TrajectoryFormatError, RecordingError, UsageError, OSError) as exc:
        # Input errors only: a malformed file, a wrong option, a missing file, a directory where
        # a file was expected, permissions. Any other exception is a bug: it keeps its traceback.
        print(f"gazebot: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    return int(result or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
