"""Reference pages generated from their one source: the CLI from its argparse parsers, the
topics from :mod:`gazebot.io.ros2.topics`. The documentation site (``make docs``) builds them at
build time, so they never drift from the code."""

from __future__ import annotations

import argparse
import os
from collections.abc import Iterator

from gazebot.apps.cli import build_parser

#: Help text is wrapped at this width, whatever the terminal (stable pages).
HELP_COLUMNS = 100


def _commands(
    parser: argparse.ArgumentParser, path: tuple[str, ...] = ("gazebot",)
) -> Iterator[tuple[tuple[str, ...], argparse.ArgumentParser]]:
    """Every parser of the command tree, depth first, with its command path."""
    yield path, parser
    for action in parser._actions:  # argparse exposes sub-commands only here
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _commands(sub, (*path, name))


def cli_markdown() -> str:
    """The command-line reference: every command's ``--help``, as the CLI prints it."""
    old = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = str(HELP_COLUMNS)  # argparse reads the width from here
    try:
        parts = [
            "# Command-line reference\n",
            "Generated from the `gazebot` command's own parsers at documentation build time; "
            "`gazebot COMMAND --help` prints the same.\n",
        ]
        for path, parser in _commands(build_parser()):
            parser.prog = " ".join(path)
            usage = parser.format_help().rstrip()
            parts.append(f"## `{' '.join(path)}`\n\n```text\n{usage}\n```\n")
    finally:
        if old is None:
            os.environ.pop("COLUMNS", None)
        else:
            os.environ["COLUMNS"] = old
    return "\n".join(parts)


def topics_markdown() -> str:
    """The topic table: every topic gazebot speaks, its ROS 2 type and its size cap."""
    from gazebot.io.ros2 import topics

    rows = [
        "# Topics and message types\n",
        "Generated from `gazebot/io/ros2/topics.py`, the table the transport and the MCAP recorder "
        f"share. Relative names live under the namespace (default `{topics.DEFAULT_NAMESPACE}`).\n",
        "| topic | type | largest payload decoded |",
        "| --- | --- | --- |",
    ]
    for topic in topics.ALL:
        rows.append(f"| `{topic.name}` | `{topic.type}` | {topic.max_bytes:,} B |")
    return "\n".join(rows) + "\n"
