"""The ``gazebot`` command line: one module per command group, each with ``register(subparsers)``.

Angles on the command line are in degrees unless an option says otherwise; everything inside is SI.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from gazebot import __version__
from gazebot.apps.cli.errors import UsageError
from gazebot.apps.cli.extras import extra_for_command, missing_extra_message
from gazebot.core.config import ConfigError
from gazebot.io.recordings import RecordingError

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
    "router",
    "bus_init",
    "study",
    "gps",
    "bip",
    "topic",
    "mcap",
    "node",
    "robots",
    "view",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="gazebot",
        description="Robot gaze behavior engine for human-to-robot handovers.",
    )
    parser.add_argument("--version", action="version", version=f"gazebot {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMAND_MODULES:
        module = importlib.import_module(f"gazebot.apps.cli.{name}")
        module.register(sub)
    _plain_help(parser)
    return parser


def _plain_help(parser: argparse.ArgumentParser) -> None:
    """Strip the reST literal markup (````x````) that module docstrings used as descriptions
    carry: ``--help`` is read in a terminal. In place, for every sub-command."""
    parser.description = _plain(parser.description)
    for action in parser._actions:
        action.help = _plain(action.help)
        if isinstance(action, argparse._SubParsersAction):
            for choice in action._choices_actions:
                choice.help = _plain(choice.help)
            for sub in set(action.choices.values()):
                _plain_help(sub)


def _plain(text: str | None) -> str | None:
    return None if text is None else text.replace("``", "")


def command_name(parser: argparse.ArgumentParser, argv: list[str]) -> str:
    """The (sub-)command ``argv`` runs, e.g. ``gazebot gps train``: its leading words that
    name a sub-command, level by level."""
    words = [parser.prog]
    for token in argv:
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        if token.startswith("-") or not subs or token not in subs[0].choices:
            break
        words.append(token)
        parser = subs[0].choices[token]
    return " ".join(words)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    argv = sys.argv[1:] if argv is None else argv
    args = parser.parse_args(argv)
    try:
        result = args.func(args)
        sys.stdout.flush()
    except ModuleNotFoundError as exc:
        # A package of an extra the core install leaves out: say which extra, in one line.
        # A missing module of no extra is a broken install or a bug: it keeps its traceback.
        command = command_name(parser, argv)
        extra = extra_for_command(command.split()[1:], exc.name)
        if extra is None:
            raise
        print(f"gazebot: error: {missing_extra_message(command, exc.name, extra)}",
              file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader went away (e.g. `| head`): not an error of ours. Point stdout at devnull so
        # the interpreter's final flush does not complain again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except (ConfigError, RecordingError, UsageError, OSError) as exc:
        # Input errors only: a malformed file, a wrong option, a missing file, a directory where
        # a file was expected, permissions. Any other exception is a bug: it keeps its traceback.
        # A file name that is not UTF-8 is kept as surrogates: shown escaped, not a crash.
        text = str(exc).encode("utf-8", "backslashreplace").decode("utf-8")
        print(f"gazebot: error: {text}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    except Exception as exc:
        # A node that cannot join the bus (its port taken, a bad endpoint) is not a bug.
        from gazebot.apps.cli.bus import bus_failure

        message = bus_failure(exc)
        if message is None:
            raise
        print(f"gazebot: error: {message}", file=sys.stderr)
        return 2
    return int(result or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
