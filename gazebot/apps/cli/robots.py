"""``gazebot robots``: the robots gazebot knows (``list``) and what the engine makes of a robot
YAML (``check``): head chain, limits, gaze frame, eyes and how much of a workspace the gaze
reaches. Angles are printed in degrees."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

from gazebot.apps.cli.errors import UsageError

EXIT_UNUSABLE = 1  # the model loads but the engine cannot point its gaze with it


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``robots`` command group (``list``, ``check``)."""
    parser = sub.add_parser(
        "robots",
        help="list the robots and check a robot YAML (URDF or MJCF)",
        description="The robots gazebot ships and checks of a robot described by its own "
        "URDF or MJCF (docs/your-robot.md).",
    )
    group = parser.add_subparsers(dest="robots_command", metavar="SUBCOMMAND")
    group.required = True
    lister = group.add_parser("list", help="the shipped robots and the example robot YAMLs")
    lister.set_defaults(func=handle_list)
    check = group.add_parser(
        "check",
        help="print what the engine will use for a robot YAML; exit 1 if it cannot use it",
        description="Load a robot YAML and its model as the engine does and print the head "
        "chain, joint limits, gaze frame, eyes and the share of a workspace ball the head "
        "alone and head plus eyes look at (within 0.5 deg), with the worst miss. Exits 2 on a "
        "malformed YAML or model, 1 when the head cannot point the gaze.",
    )
    check.add_argument("robot", help="robot YAML (or a shipped robot's name)")
    add_package_path(check)
    check.add_argument(
        "--radius", type=float, default=2.0, help="workspace radius around the gaze, m (2)"
    )
    check.add_argument("--json", action="store_true", help="print one JSON document")
    check.set_defaults(func=handle_check)


def add_package_path(parser: argparse.ArgumentParser) -> None:
    """The ``--package-path DIR`` option (repeatable) for ``package://`` URIs."""
    parser.add_argument(
        "--package-path",
        action="append",
        default=[],
        metavar="DIR",
        help="folder holding ROS packages for package:// URIs (repeatable; searched before "
        "ROS_PACKAGE_PATH and installed cmeel prefixes)",
    )


def handle_list(args: argparse.Namespace) -> int:
    """Run ``gazebot robots list``."""
    from gazebot.core.config import configs_dir
    from gazebot.core.kinematics.robot_config import load_robot_config

    folder = configs_dir() / "robots"
    for path in sorted(folder.glob("*.yaml")) + sorted(folder.glob("examples/*.yaml")):
        config, _ = load_robot_config(path)
        model = f"mjcf {config.mjcf}" if config.mjcf is not None else f"urdf {config.urdf}"
        label = path.stem if path.parent == folder else str(path.relative_to(folder.parent.parent))
        print(f"{label:<34s} head {len(config.head_joints)}  {model}")
    return 0


def handle_check(args: argparse.Namespace) -> int:
    """Run ``gazebot robots check``.

    Raises:
        ConfigError, FileNotFoundError: a malformed YAML or model, a missing file.
    """
    from gazebot.core.kinematics import RobotModel
    from gazebot.core.kinematics.reach import ON_TARGET, gaze_reach
    from gazebot.core.kinematics.robot_config import with_package_path

    if not (math.isfinite(args.radius) and args.radius > 0.0):
        raise UsageError(f"--radius must be a positive number of metres, got {args.radius}")
    robot = RobotModel.load(with_package_path(args.robot, tuple(args.package_path)))
    report = describe(robot)
    reach = gaze_reach(robot, radius=args.radius)
    report["reach"] = {
        "radius_m": reach.radius,
        "samples": reach.samples,
        "on_target_deg": math.degrees(ON_TARGET),
        "head_share": reach.head_share,
        "head_and_eyes_share": reach.gaze_share,
        "worst_miss_deg": math.degrees(reach.worst_miss),
        "worst_point_m": list(reach.worst_point),
    }
    problems = usability_problems(robot, reach.gaze_share)
    report["problems"] = problems
    if args.json:
        print(json.dumps(report))
    else:
        print_report(report)
    return EXIT_UNUSABLE if problems else 0


def describe(robot: Any) -> dict[str, Any]:
    """What the engine uses of ``robot`` (a :class:`RobotModel`), degrees at the surface."""
    import numpy as np

    config = robot.config
    override = config.head_velocity_limits_deg_s
    joints = [
        {
            "name": name,
            "lower_deg": math.degrees(lo),
            "upper_deg": math.degrees(hi),
            "velocity_deg_s": math.degrees(v),
            "velocity_from": "yaml" if name in override else "model",
        }
        for name, lo, hi, v in zip(
            robot.head_joints, robot.lower, robot.upper, robot.velocity_limits, strict=True
        )
    ]
    pose = robot.gaze_pose(robot.rest)
    if robot.eye_chains:
        eyes: dict[str, Any] = {"kind": "joints", "joints": robot.eye_joints}
    elif config.display is not None:
        d = config.display
        eyes = {"kind": "display", "display": f"{d.width_px}x{d.height_px} px, "
                f"{d.diagonal_in:g} in", "style": config.eye_style}
    else:
        eyes = {"kind": "none"}
    eyes.update(
        yaw_range_deg=[math.degrees(v) for v in robot.eye_yaw_range],
        pitch_range_deg=[math.degrees(v) for v in robot.eye_pitch_range],
    )
    chain = [robot.model.names[j] for j in range(1, robot.model.njoints)]
    spec = config.gaze_frame
    return {
        "robot": robot.name,
        "model": {"kind": robot.model_kind, "file": str(robot.mjcf_path)},
        "head_chain": chain,
        "passive_joints": list(robot.passive_joints),
        "head_joints": joints,
        "gaze_frame": {
            "name": config.gaze_site,
            "link": spec.link if spec is not None else None,
            "origin_at_rest_m": np.round(pose.position, 4).tolist(),
            "line_of_sight_at_rest": np.round(pose.line_of_sight, 4).tolist(),
        },
        "gaze_mode": robot.gaze_mode,
        "eyes": eyes,
    }


def usability_problems(robot: Any, gaze_share: float) -> list[str]:
    """Why the engine cannot point ``robot``'s gaze (empty when it can)."""
    import numpy as np

    problems = []
    if robot.n_head:
        _, J = robot.gaze_jacobian(robot.rest)
        for name, column in zip(robot.head_joints, np.asarray(J).T, strict=True):
            if float(np.linalg.norm(column[3:])) < 1e-9:
                problems.append(f"head joint {name!r} does not turn the gaze frame")
    if gaze_share == 0.0:
        problems.append("the gaze reaches no point of the workspace")
    return problems


def print_report(report: dict[str, Any]) -> None:
    """The human-readable ``robots check`` report."""
    model = report["model"]
    print(f"robot {report['robot']}: {model['kind']} {Path(model['file'])}")
    print(f"  head chain (base to gaze): {' -> '.join(report['head_chain']) or '(fixed)'}")
    if report["passive_joints"]:
        print(f"  carried by (held, not commanded): {', '.join(report['passive_joints'])}")
    for j in report["head_joints"]:
        print(
            f"  {j['name']:<16s} [{j['lower_deg']:8.2f}, {j['upper_deg']:8.2f}] deg  "
            f"{j['velocity_deg_s']:8.2f} deg/s ({j['velocity_from']})"
        )
    g = report["gaze_frame"]
    on = f" on link {g['link']}" if g["link"] else ""
    print(f"  gaze frame {g['name']}{on}: at rest origin {g['origin_at_rest_m']} m, "
          f"looking along {g['line_of_sight_at_rest']}")
    e = report["eyes"]
    what = {"display": f"drawn on a {e.get('display')} screen ({e.get('style')})",
            "joints": f"joints {', '.join(e.get('joints', []))}", "none": "none"}[e["kind"]]
    print(f"  eyes: {what}; yaw {e['yaw_range_deg'][0]:.1f}..{e['yaw_range_deg'][1]:.1f} deg, "
          f"pitch {e['pitch_range_deg'][0]:.1f}..{e['pitch_range_deg'][1]:.1f} deg "
          f"(gaze mode {report['gaze_mode']})")
    r = report["reach"]
    print(f"  workspace: {r['samples']} points within {r['radius_m']:g} m in front of the gaze; "
          f"within {r['on_target_deg']:g} deg: head alone {100 * r['head_share']:.1f}%, "
          f"head and eyes {100 * r['head_and_eyes_share']:.1f}%")
    worst = ", ".join(f"{v:.2f}" for v in r["worst_point_m"])
    print(f"  worst miss {r['worst_miss_deg']:.1f} deg (at {worst} m)")
    for p in report["problems"]:
        print(f"  problem: {p}")
    print("  ok: the engine can use this robot" if not report["problems"] else
          "  the engine cannot use this robot")


def is_urdf_robot(robot: str) -> bool:
    """Whether the robot (name or YAML) is described by a URDF (``gazebot demo`` then runs the
    engine against a kinematic head: the MuJoCo handover scene needs an MJCF arm and gripper).

    Raises:
        FileNotFoundError, ConfigError: unknown robot, malformed YAML.
    """
    from gazebot.core.kinematics.robot_config import load_robot_config

    return load_robot_config(robot)[0].urdf is not None


def run_kinematic_demo(args: argparse.Namespace) -> int:
    """``gazebot demo --robot FILE.yaml`` for a URDF robot: the gaze engine against a kinematic
    head in a synthetic handover; writes ``timeline.csv`` into ``--out`` and prints a summary.

    Raises:
        UsageError: ``--out`` is not a folder, or ``--gaze-mode`` unknown.
        ConfigError, FileNotFoundError: a malformed robot YAML or model.
    """
    from gazebot.apps.cli.errors import robot_with_gaze_mode
    from gazebot.apps.sim.kinematic_head import (
        run_kinematic_head,
        synthetic_handover,
        write_kinematic_csv,
    )
    from gazebot.core.kinematics import RobotModel
    from gazebot.core.kinematics.robot_config import with_package_path

    out: Path = args.out
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out} exists and is not a folder")
    config = with_package_path(args.robot, tuple(getattr(args, "package_path", ())))
    robot = RobotModel.load(robot_with_gaze_mode(config, getattr(args, "gaze_mode", None)))
    ticks = run_kinematic_head(robot, synthetic_handover(robot), args.behavior)
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / "timeline.csv"
    write_kinematic_csv(ticks, csv_path)
    phases = list(dict.fromkeys(t.phase for t in ticks))
    summary: dict[str, Any] = {
        "robot": robot.name,
        "head": "kinematic (URDF robot: no MuJoCo handover scene)",
        "timeline_csv": str(csv_path),
        "duration_s": round(ticks[-1].t, 4),
        "phases": phases,
        "targets": list(dict.fromkeys(t.target for t in ticks)),
        "final_miss_deg": math.degrees(ticks[-1].miss),
    }
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"gazebot demo: {robot.name} with a kinematic head (a URDF robot has no MuJoCo "
              f"handover scene); {len(ticks)} ticks, {summary['duration_s']:.2f} s")
        print(f"  phases: {' -> '.join(phases)}; targets: {', '.join(summary['targets'])}")
        print(f"  final gaze miss {summary['final_miss_deg']:.3f} deg; timeline: {csv_path}")
    return 0
