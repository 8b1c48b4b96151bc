"""``gazebot ik``: solve the look-at IK for one target and print head joints, eyes and residuals."""

from __future__ import annotations

import argparse
import json
import math

from gazebot.apps.cli.choices import add_robot_argument
from gazebot.apps.cli.errors import UsageError


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``ik`` command."""
    parser = sub.add_parser(
        "ik",
        help="point the robot's head (and eyes) at a 3D target",
        description=(
            "Solve the look-at IK: head joint goals that point the display's line of sight at "
            "TARGET (m, robot base frame), the eye yaw/pitch for what the head cannot do, and "
            "the residual pointing errors. JSON angles are in rad, residuals in degrees."
        ),
    )
    add_robot_argument(parser)
    parser.add_argument(
        "--target",
        nargs=3,
        type=float,
        required=True,
        metavar=("X", "Y", "Z"),
        help="target point in the robot base frame (m)",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON document")
    parser.set_defaults(func=handle)


def handle(args: argparse.Namespace) -> int:
    """Run ``gazebot ik``.

    Raises:
        ValueError, ConfigError, FileNotFoundError: bad target, robot file or robot name.
    """
    from gazebot.core.kinematics import RobotModel, solve_ik

    target = [float(v) for v in args.target]
    if not all(math.isfinite(v) for v in target):
        raise UsageError(f"--target must be three finite numbers (m), got {target}")
    robot = RobotModel.load(args.robot)
    sol = solve_ik(robot, target)
    if not sol.valid:
        raise UsageError(f"cannot look at {target}: {sol.message}")
    if args.json:
        print(json.dumps(sol.to_json()))
        return 0
    print(f"robot {robot.name}: look at ({target[0]:.3f}, {target[1]:.3f}, {target[2]:.3f}) m")
    for name, value in sol.joints.items():
        print(f"  {name:<12s} {math.degrees(value):8.2f} deg")
    print(
        f"  eyes yaw {math.degrees(sol.eye_yaw):7.2f} deg, "
        f"pitch {math.degrees(sol.eye_pitch):7.2f} deg"
    )
    print(
        f"  residual: head {math.degrees(sol.residual):.3f} deg, "
        f"after eyes {math.degrees(sol.total_residual):.3f} deg"
    )
    if sol.message:
        print(f"  note: {sol.message}")
    return 0
