"""``gazebot behaviors``: list the available gaze behaviors or show one."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from gazebot.apps.cli.errors import UsageError


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser("behaviors", help="list or show gaze behaviors")
    cmds = parser.add_subparsers(dest="behaviors_command", metavar="ACTION")
    cmds.required = True

    p = cmds.add_parser("list", help="list built-in and user behaviors")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument(
        "--dir",
        action="append",
        type=Path,
        default=None,
        help="user behavior folder (repeatable; default: $GAZEBOT_BEHAVIORS_PATH)",
    )
    p.set_defaults(func=_list)

    p = cmds.add_parser("show", help="print a behavior's resolved definition (or its diagram)")
    p.add_argument("behavior", help="behavior name or YAML file")
    p.add_argument("--dir", action="append", type=Path, default=None, help="user behavior folder")
    p.add_argument(
        "--diagram",
        type=Path,
        default=None,
        metavar="FILE",
        help="write the behavior's state machine diagram as Mermaid text (FILE.md: in a fenced "
        "mermaid block; any other name, e.g. FILE.mmd: the bare diagram)",
    )
    p.set_defaults(func=_show)


def _list(args: argparse.Namespace) -> int:
    from gazebot.core.behaviors import list_behaviors

    infos = list_behaviors(args.dir)
    if args.json:
        print(json.dumps({"behaviors": [i.to_json() for i in infos]}, indent=2))
        return 0
    width = max((len(i.name) for i in infos), default=4)
    for info in infos:
        origin = "" if info.builtin else f"  [{info.path}]"
        variant = f" (variant of {info.extends})" if info.extends else ""
        print(f"{info.name:<{width}}  {info.description}{variant}{origin}")
    return 0


def _show(args: argparse.Namespace) -> int:
    from gazebot.core.behaviors import load_behavior

    spec = load_behavior(args.behavior, args.dir)
    if args.diagram is not None:
        from gazebot.core.behaviors.machine import write_diagram

        if not Path(args.diagram).parent.is_dir():
            raise UsageError(f"--diagram {args.diagram}: output folder does not exist")
        write_diagram(spec, args.diagram)
        print(f"wrote {args.diagram} (state machine of {spec.name})")
        return 0
    print(json.dumps(spec.model_dump(mode="json"), indent=2))
    return 0
