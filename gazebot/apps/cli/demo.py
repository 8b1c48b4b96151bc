"""``gazebot demo``: the main job. Simulates a human-to-robot handover in MuJoCo with the gaze
engine driving the robot's head and eyes, and writes ``handover.mp4``, ``timeline.csv``,
``timeline.png`` and ``handover.mcap`` (every ROS 2 topic of the run, log time = wall clock,
header stamps = simulation time) into the output folder."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

from gazebot.apps.cli.argtypes import seed_value
from gazebot.apps.cli.choices import (
    add_behavior_argument,
    add_gaze_mode_argument,
    add_robot_argument,
    add_scene_argument,
)
from gazebot.apps.cli.errors import UsageError, option_error, robot_with_gaze_mode
from gazebot.apps.cli.robots import add_package_path, is_urdf_robot, run_kinematic_demo
from gazebot.apps.render.video_settings import VIDEO
from gazebot.core.defaults import DEFAULT_BEHAVIOR, DEFAULT_ROBOT

if TYPE_CHECKING:
    from gazebot.core.kinematics.robot_config import RobotConfig
    from gazebot.io.ros2.handover_log import HandoverMcap

EXIT_INFEASIBLE = 3  # the reach controller found no feasible reach and the robot stopped

# The scene's controller fields the command line sets, for error messages.
_OPTIONS = {
    "reach_time_s": "--reach-time",
    "stall_time_s": "--stall-time",
    "retreat": "--retreat",
    "policy": "--policy",
}


def register(sub: argparse._SubParsersAction) -> None:
    from gazebot.apps.sim.scene_config import reach_controller_names

    parser = sub.add_parser(
        "demo",
        help="simulate a handover with gaze and write a video, a timeline CSV and a plot",
        description=__doc__,
    )
    add_robot_argument(parser, default=None,
                       default_help=f"panda with --controller gps, else {DEFAULT_ROBOT}")
    add_package_path(parser)
    add_behavior_argument(parser, default=DEFAULT_BEHAVIOR)
    add_scene_argument(parser)
    add_gaze_mode_argument(parser)
    parser.add_argument("--out", type=Path, default=Path("out/demo"), help="output folder")
    parser.add_argument("--seed", type=seed_value, default=0, help="random seed (default: 0)")
    parser.add_argument("--width", type=int, default=VIDEO.width,
                        help=f"video width, px (default: {VIDEO.width})")
    parser.add_argument("--height", type=int, default=VIDEO.height,
                        help=f"video height, px (default: {VIDEO.height})")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    parser.add_argument(
        "--no-inset",
        action="store_true",
        help="no close-up of the robot's head screen in the video's corner (default: the scene's)",
    )
    parser.add_argument("--json", action="store_true", help="print a JSON summary to stdout")
    parser.add_argument(
        "--controller",
        choices=reach_controller_names(),
        help="the robot's reach controller (default: the scene's; seed chapters 3-4)",
    )
    parser.add_argument(
        "--policy",
        type=Path,
        metavar="DIR",
        help="--controller gps: the learned policy (`gazebot gps train --out DIR`); "
        "runs on --robot panda",
    )
    parser.add_argument(
        "--reach-time", type=float, help="'Reach before', s from the handover's start"
    )
    parser.add_argument(
        "--stall-time", type=float, help="'Don't move until', s from the handover's start (mce)"
    )
    parser.add_argument(
        "--retreat",
        choices=["after-release", "after-grasp"],
        help="when the robot retreats (seed 6.3: after the release; 6.4.3: after grasping)",
    )
    add_giver_motion_options(parser)
    parser.set_defaults(func=run_demo)


def add_giver_motion_options(parser: argparse.ArgumentParser) -> None:
    """``--giver-motion FILE`` and its point names: replay a recorded giver's hand and face."""
    from gazebot.apps.cli.phases import add_recording_options

    parser.add_argument(
        "--giver-motion",
        default=None,
        metavar="FILE",
        help="replay a recorded giver (CSV, C3D, ROS bag, pose folder), retargeted so the "
        "recorded hand meets the robot's handover location",
    )
    add_recording_options(parser)


def giver_factory(args: argparse.Namespace):
    """The recorded giver of ``--giver-motion`` (``None``: the simulated giver)."""
    if getattr(args, "giver_motion", None) is None:
        return None
    from gazebot.apps.sim.giver_replay import load_giver_motion

    return load_giver_motion(
        args.giver_motion, args.giver_hand, args.receiver_hand, args.giver_face,
        args.unit, args.rate,
    )


def scene_with_overrides(args: argparse.Namespace):
    """The scene named by ``--scene`` with the controller options and ``--no-inset`` applied
    (validated), or the scene name itself when no option is given."""
    overrides = {
        key: value
        for key, value in (
            ("reach_controller", getattr(args, "controller", None)),
            ("reach_time_s", getattr(args, "reach_time", None)),
            ("stall_time_s", getattr(args, "stall_time", None)),
            ("retreat", getattr(args, "retreat", None)),
            ("policy", None if getattr(args, "policy", None) is None else str(args.policy)),
        )
        if value is not None
    }
    if getattr(args, "no_inset", False):
        from gazebot.apps.sim.scene_config import with_inset

        base = with_inset(args.scene, False)
    else:
        base = args.scene
    from gazebot.apps.sim.scene_config import GPS_REACH, load_scene

    if not overrides:
        ctrl = load_scene(base).controller  # a scene YAML may ask for the learned reach itself
        if ctrl.reach_controller == GPS_REACH:
            check_policy(ctrl.policy, default_robot(args))
        return base
    from gazebot.apps.sim.cartesian_reach import scene_controllers_config
    from gazebot.apps.sim.scene_config import (
        JOINT_REACH,
        Direction,
        SceneConfig,
        reach_controller_names,
    )

    data = load_scene(base).model_dump()
    data["controller"].update(overrides)
    controller = str(data["controller"]["reach_controller"])
    timed = "reach_time_s" in overrides or "stall_time_s" in overrides
    if timed and controller == "joint":
        *others, last = (n for n in reach_controller_names() if n != JOINT_REACH)
        need = f"{', '.join(others)} or {last}"
        raise UsageError(f"--reach-time/--stall-time need --controller {need}")
    if "stall_time_s" in overrides and controller != "mce":
        raise UsageError("--stall-time ('Don't move until') is the mce controller's")
    if controller == GPS_REACH and data["controller"].get("policy") is None:
        raise UsageError("--controller gps needs --policy DIR (written by `gazebot gps train "
                         "--out DIR`)")
    if "policy" in overrides and controller != GPS_REACH:
        raise UsageError("--policy is the learned controller's: it needs --controller gps")
    try:
        scene = SceneConfig.model_validate(data)
        if scene.controller.reach_controller not in (JOINT_REACH, GPS_REACH):
            # The reach and stall times against the controllers YAML, as the simulation will.
            scene_controllers_config(scene.controller, scene.direction is Direction.ROBOT_TO_HUMAN)
    except ValueError as exc:  # pydantic's ValidationError is one; it names the field
        raise option_error(exc, _OPTIONS, "invalid controller options") from exc
    if scene.controller.reach_controller == GPS_REACH:
        check_policy(scene.controller.policy, default_robot(args))
    return scene


def check_policy(policy: str | None, robot: str) -> None:
    """Before any simulation: the ``gps`` policy loads and fits ``robot`` (one-line errors)."""
    import mujoco

    from gazebot.apps.controllers import CONTROLLERS
    from gazebot.apps.sim.policy_reach import PolicyReach
    from gazebot.apps.sim.robot import load_sim_robot
    from gazebot.apps.sim.scene_config import GPS_REACH
    from gazebot.apps.sim.torque_arm import arm_actuator, is_torque_motor
    from gazebot.core.config import ConfigError

    try:
        controller = CONTROLLERS.make(GPS_REACH, None, policy=policy)
    except (ConfigError, ValueError) as exc:
        raise UsageError(f"--policy {policy}: {exc}") from None
    try:
        sim_robot = load_sim_robot(robot)
    except (FileNotFoundError, ConfigError):
        return  # the robot's own error comes later, from its loader
    model = mujoco.MjModel.from_xml_path(str(sim_robot.mjcf))
    acts = [arm_actuator(model, j) for j in sim_robot.arm_joints]
    if len(acts) != 7 or not all(a >= 0 and is_torque_motor(model, a) for a in acts):
        raise UsageError(f"--controller gps drives the Panda learner's seven joint torques: "
                         f"--robot {robot} has no such arm (use --robot panda)")
    try:
        PolicyReach(controller, model, mujoco.MjData(model), sim_robot.arm_joints,
                    sim_robot.gripper_site)
    except (KeyError, ValueError) as exc:
        raise UsageError(f"--robot {robot}: {exc}") from None


def default_robot(args: argparse.Namespace) -> str:
    """``--robot``, else the robot the reach controller (``--controller``, else the scene's)
    runs on: the learned ``gps`` policy drives the Panda it was trained on; every other
    controller defaults to the Sawyer."""
    if args.robot is not None:
        return str(args.robot)
    from gazebot.apps.sim.scene_config import GPS_REACH, load_scene

    controller = getattr(args, "controller", None)
    if controller is None:
        controller = load_scene(args.scene).controller.reach_controller
    return "panda" if controller == GPS_REACH else DEFAULT_ROBOT


def run_demo(args: argparse.Namespace) -> int:
    from gazebot.core.kinematics.robot_config import GAZE_MODES

    args.robot = default_robot(args)
    from gazebot.apps.cli.behaviors import robot_points
    from gazebot.core.behaviors import load_behavior

    # Before any simulation: a wrong behavior file fails now, naming its file and line.
    load_behavior(args.behavior, None, robot_points(args.robot))
    if is_urdf_robot(args.robot):
        return run_kinematic_demo(args)
    from gazebot.apps.render.gl_check import OffscreenRenderingError
    from gazebot.apps.render.timeline import phase_spans, plot_timeline, write_timeline_csv

    if args.gaze_mode is not None and args.gaze_mode not in GAZE_MODES:
        raise UsageError(
            f"--gaze-mode must be one of {', '.join(GAZE_MODES)}, not {args.gaze_mode!r}"
        )
    from gazebot.apps.sim.record import check_video_size

    try:
        check_video_size(args.width, args.height, 30.0)  # the demo records at 30 frames/s
    except ValueError as exc:
        raise UsageError(f"--width/--height: {exc}") from None
    out: Path = args.out
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out} exists and is not a folder")
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    from gazebot.apps.render.gl_check import ensure_gl_backend

    try:
        # Before anything loads MuJoCo (the gps policy check loads a model): the first working
        # of EGL and OSMesa, unless MUJOCO_GL says.
        ensure_gl_backend()
    except OffscreenRenderingError as exc:
        print(f"gazebot: error: {exc}", file=sys.stderr)
        return 2
    from gazebot.apps.sim.policy_reach import PolicyReachLog
    from gazebot.apps.sim.stl_monitor import HandoverMonitor

    monitor = HandoverMonitor()  # the seed's Table 4.2 specs over the run (4.2.1 robustness)
    learned = PolicyReachLog()  # what a learned (gps) reach did, if one ran

    def on_tick(sim, tick) -> None:
        monitor.on_tick(sim, tick)
        learned.on_tick(sim, tick)

    try:
        rec = _record(args, out, on_tick)
    except OffscreenRenderingError as exc:
        print(f"gazebot: error: {exc}", file=sys.stderr)
        return 2
    from gazebot.apps.controllers import INFEASIBLE_MESSAGE
    from gazebot.core.types import EventKind

    infeasible = [e for e in rec.robot_events if e.kind is EventKind.ROBOT_REACH_INFEASIBLE]
    if infeasible:
        # The seed's failure feedback (3.2), to the user before anything else.
        print(INFEASIBLE_MESSAGE, file=sys.stderr if args.json else sys.stdout)
    csv_path = write_timeline_csv(rec.ticks, out / "timeline.csv")
    title = f"{Path(str(args.robot)).stem} - {Path(str(args.behavior)).stem} - {args.scene}"
    png_path = plot_timeline(rec.ticks, out / "timeline.png", title=title)
    summary = {
        "video": str(rec.video),
        "mcap": str(out / "handover.mcap"),
        "timeline_csv": str(csv_path),
        "timeline_png": str(png_path),
        "frames": rec.frames,
        "fps": rec.fps,
        "duration_s": round(rec.ticks[-1].t, 4),
        "completed": rec.completed and not infeasible,
        "phases": [
            {"phase": p, "start": round(a, 3), "end": round(b, 3)}
            for p, a, b in phase_spans(rec.ticks)
        ],
        "robot_events": [e.to_json() for e in rec.robot_events],
        "reach_infeasible": bool(infeasible),
        "reach_start_time_s": _last_reach_start_time(rec.ticks),
        "stl_robustness": {k: round(v, 4) for k, v in monitor.robustness().items()},
        "wall_time_s": round(time.perf_counter() - t0, 2),
    }
    if learned.summary() is not None:
        summary["gps"] = learned.summary()
    if args.json:
        print(json.dumps(summary))
    else:
        phases = " -> ".join(p["phase"] for p in summary["phases"])
        print(
            f"handover {summary['duration_s']:.2f} s ({phases}), {rec.frames} frames, "
            f"{summary['wall_time_s']:.1f} s wall"
        )
        rob = ", ".join(f"{k} {v:+.3f}" for k, v in summary["stl_robustness"].items())
        print(f"STL robustness (Table 4.2, positive = met): {rob}")
        if "gps" in summary:
            g = summary["gps"]
            print(f"learned reach ({g['policy_state']} state): gripper to the object "
                  f"{g['object_gap_start_m']} -> {g['object_gap_end_m']} m in {g['reach_s']} s, "
                  f"max |torque| {g['max_torque_nm']} N m, fallbacks {g['fallbacks']}")
        for path in (rec.video, csv_path, png_path, out / "handover.mcap"):
            print(f"wrote {path}")
    if infeasible:
        # The robot stopped and said so: a run that ended as the seed says it should, but no
        # handover happened.
        print(
            f"gazebot: the reach was infeasible at {infeasible[0].t:.2f} s: the robot stopped "
            f"(exit {EXIT_INFEASIBLE})",
            file=sys.stderr,
        )
        return EXIT_INFEASIBLE
    if not rec.completed:
        print("gazebot: warning: the handover did not finish in time; the video is cut")
        return 1
    return 0


def _last_reach_start_time(ticks) -> float | None:
    """The seed's reach-start time (giver's reach start - robot's, s) once both started."""
    import math

    value = ticks[-1].reach_start_time if ticks else math.nan
    return None if math.isnan(value) else round(value, 4)


def _record(args: argparse.Namespace, out: Path, on_tick=None):
    from gazebot.apps.sim.record import record_handover

    robot = robot_with_gaze_mode(args.robot, args.gaze_mode)
    log = handover_mcap(robot, out / "handover.mcap")
    try:
        rec = record_handover(
            robot=robot,
            behavior=args.behavior,
            scene=scene_with_overrides(args),
            on_tick=on_tick,
            out_path=out / "handover.mp4",
            seed=args.seed,
            width=args.width,
            height=args.height,
            progress=not args.no_progress,
            giver_factory=giver_factory(args),
            on_step=log.tick,
        )
    except BaseException:
        log.abort()
        raise
    log.close()
    return rec


def handover_mcap(robot: str | Path | RobotConfig, path: Path) -> HandoverMcap:
    """The MCAP log of a demo run on ``robot`` (name, YAML or config): every topic, eye images
    at 5 Hz from the robot's own eye renderer (JPEG at the display's size costs milliseconds)."""
    from gazebot.apps.render import EyeRenderer
    from gazebot.apps.sim.record import CONTROL_HZ
    from gazebot.core.kinematics.robot import RobotModel
    from gazebot.core.kinematics.robot_config import RobotConfig, load_robot_config
    from gazebot.io.ros2.handover_log import HandoverMcap

    config = robot if isinstance(robot, RobotConfig) else load_robot_config(robot)[0]
    eyes = EyeRenderer.for_robot(config)
    return HandoverMcap(
        path, config.base_frame, config.gaze_site, 1.0 / CONTROL_HZ,
        eye_image=lambda yaw, pitch, blink, distance: eyes.render(
            yaw, pitch, blink=blink, distance=distance),
        eye_image_period=0.2,
        robot=RobotModel.load(robot),  # /robot_description, /tf, /tf_static, markers
    )
