"""``gazebot render eyes|video``: the group; each kind lives in its own module."""

from __future__ import annotations

import argparse

from gazebot.apps.cli import render_eyes, render_video


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser("render", help="render eye images or handover videos off-screen")
    kinds = parser.add_subparsers(dest="render_kind", metavar="KIND")
    kinds.required = True
    render_eyes.register(kinds)
    render_video.register(kinds)
