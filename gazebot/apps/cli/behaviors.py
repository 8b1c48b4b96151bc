"""``gazebot behaviors``: list the available gaze behaviors, show one or validate files."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from gazebot.apps.cli.choices import add_robot_argument
from gazebot.apps.cli.errors import UsageError


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser("behaviors", help="list, show or validate gaze behaviors")
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
    add_robot_argument(p)
    p.set_defaults(func=_show)

    p = cmds.add_parser(
        "validate",
        help="check behavior files as the engine would (exit 2 on any error)",
        description="Check every file as the engine would load it on --robot: YAML syntax, "
        "keys, types, phases, at: fractions, $parameter and after: event references, durations "
        "and targets (tracked ones or the robot's points). Every error is printed as "
        "FILE:LINE: FIELD: PROBLEM; the exit status is 2 if any file has one, else 0.",
    )
    p.add_argument("files", nargs="+", metavar="FILE", help="behavior YAML file (or name)")
    p.add_argument("--dir", action="append", type=Path, default=None, help="user behavior folder")
    add_robot_argument(p)
    p.set_defaults(func=_validate)


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


def robot_points(robot: str | Path) -> list[str]:
    """The point names of ``robot`` (a name or YAML file): the targets a behavior may name
    besides the tracked ones."""
    from gazebot.core.kinematics.robot_config import load_robot_config

    return sorted(load_robot_config(robot)[0].points)


def _validate(args: argparse.Namespace) -> int:
    from gazebot.core.behaviors import behavior_errors

    points = robot_points(args.robot)
    failed = 0
    for name in args.files:
        try:
            errors = [str(e) for e in behavior_errors(name, args.dir, points)]
        except FileNotFoundError as exc:
            errors = [f"{name}: {exc}"]
        for line in errors:
            print(line, file=sys.stderr)
        if errors:
            failed += 1
        else:
            print(f"{name}: ok")
    if failed:
        print(f"{failed} of {len(args.files)} behavior files have errors", file=sys.stderr)
        return 2
    return 0


def _show(args: argparse.Namespace) -> int:
    from gazebot.core.behaviors import load_behavior

    spec = load_behavior(args.behavior, args.dir, robot_points(args.robot))
    if args.diagram is not None:
        from gazebot.core.behaviors.machine import write_diagram

        if not Path(args.diagram).parent.is_dir():
            raise UsageError(f"--diagram {args.diagram}: output folder does not exist")
        write_diagram(spec, args.diagram)
        print(f"wrote {args.diagram} (state machine of {spec.name})")
        return 0
    print(json.dumps(spec.model_dump(mode="json"), indent=2))
    return 0
