"""``gazebot reach-plan``: plan a reach with one of the seed's controllers (pv, mcj, mce, stl) and
print the closed-loop end-effector path, its feasibility and the solve time per control step.

Points are metres in the robot base frame; times seconds from the handover's start. Exit status
is 0 also when the timing is infeasible (that is an answer, reported in the output)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from gazebot.apps.cli.errors import UsageError, option_error

# The controllers config fields the command line sets, for error messages.
_OPTIONS = {
    "reach_time_s": "--reach-time",
    "stall_time_s": "--stall-time",
    "u_max_m_s": "--u-max",
    "dt_s": "--dt",
    "horizon": "--horizon",
    "strategy": "--strategy",
    "role": "--role",
}

# A reach longer than this is no reach; the bound also keeps a typo from planning for hours.
MAX_DURATION_S = 120.0


def register(sub: argparse._SubParsersAction) -> None:
    from gazebot.apps.controllers import CONTROLLERS, planner_names
    from gazebot.apps.controllers.config import Role, Strategy

    planners = planner_names()
    p = sub.add_parser(
        "reach-plan", help=f"plan a timed reach ({', '.join(planners)})",
        description=__doc__,
    )
    p.add_argument(
        "--controller",
        required=True,
        choices=planners,
        help="; ".join(f"{n}: {CONTROLLERS.entry(n).description}" for n in planners),
    )
    p.add_argument(
        "--start",
        nargs=3,
        type=float,
        required=True,
        metavar=("X", "Y", "Z"),
        help="end-effector start (m)",
    )
    p.add_argument(
        "--hand",
        nargs=3,
        type=float,
        required=True,
        metavar=("X", "Y", "Z"),
        help="human hand (m), still (the seed's static model, eq. 3.7)",
    )
    p.add_argument(
        "--hand-velocity",
        nargs=3,
        type=float,
        metavar=("VX", "VY", "VZ"),
        help="move the hand at this constant velocity (m/s) instead",
    )
    p.add_argument(
        "--target",
        nargs=3,
        type=float,
        metavar=("X", "Y", "Z"),
        help="predetermined handover location (stl predetermined strategies)",
    )
    p.add_argument("--reach-time", type=float, help="'Reach before', s (default: config)")
    p.add_argument("--stall-time", type=float, help="'Don't move until', s (mce; default: config)")
    p.add_argument("--u-max", type=float, help="end-effector speed cap, m/s (default: config)")
    p.add_argument("--dt", type=float, help="control period, s (default: config)")
    p.add_argument("--horizon", type=int, help="L (mcj, mce) or H (stl) steps (default: config)")
    p.add_argument("--strategy", choices=[s.value for s in Strategy], help="stl strategy")
    p.add_argument("--role", choices=[r.value for r in Role], help="stl: robot receiver or giver")
    p.add_argument("--duration", type=float, help="simulated time, s (default: reach time + 1)")
    p.add_argument(
        "--config", type=Path, help="controllers YAML (default: configs/controllers.yaml)"
    )
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run_reach_plan)
    register_table(sub)


def controllers_config_from_args(args: argparse.Namespace):
    """The controllers config with the command-line overrides applied (validated)."""
    from gazebot.apps.controllers.config import ControllersConfig, load_controllers_config

    cfg = load_controllers_config(getattr(args, "config", None))
    data = cfg.model_dump()
    for opt, key in (
        ("reach_time", "reach_time_s"),
        ("stall_time", "stall_time_s"),
        ("u_max", "u_max_m_s"),
        ("dt", "dt_s"),
    ):
        if getattr(args, opt, None) is not None:
            data[key] = getattr(args, opt)
    if getattr(args, "horizon", None) is not None:
        for name in ("mcj", "mce", "stl"):
            data[name]["horizon"] = args.horizon
    if getattr(args, "strategy", None):
        data["stl"]["strategy"] = args.strategy
    if getattr(args, "role", None):
        data["stl"]["role"] = args.role
    try:
        return ControllersConfig.model_validate(data)
    except ValueError as exc:  # pydantic's ValidationError is one; it names the field
        raise option_error(exc, _OPTIONS, "invalid controller options") from exc


def run_reach_plan(args: argparse.Namespace) -> int:
    import numpy as np

    from gazebot.apps.controllers import INFEASIBLE_MESSAGE, make_controller
    from gazebot.apps.controllers.rollout import run_reach

    cfg = controllers_config_from_args(args)
    if args.stall_time is not None and args.controller != "mce":
        raise UsageError(
            "--stall-time ('Don't move until') is the mce controller's; use --controller mce"
        )
    points = {
        "--start": args.start,
        "--hand": args.hand,
        "--hand-velocity": args.hand_velocity,
        "--target": args.target,
    }
    for name, v in points.items():
        if v is not None and not np.all(np.isfinite(v)):
            raise UsageError(f"{name} must be finite, got {list(v)}")
    start = np.array(args.start, float)
    hand0 = np.array(args.hand, float)
    hand = hand0
    if args.hand_velocity is not None:
        vel = np.array(args.hand_velocity, float)
        hand = lambda t: hand0 + vel * t  # noqa: E731
    target = None if args.target is None else np.array(args.target, float)
    if args.controller == "stl" and not cfg.stl.strategy.towards_human and target is None:
        raise UsageError(
            f"--strategy {cfg.stl.strategy.value} needs --target X Y Z (the handover location)"
        )
    controller = make_controller(args.controller, cfg)
    duration = args.duration if args.duration is not None else cfg.reach_time_s + 1.0
    if not 0 < duration <= MAX_DURATION_S:
        raise UsageError(f"--duration must be in (0, {MAX_DURATION_S:g}] s, got {duration}")
    # A giving robot holds the object during its reach (Table 4.3's giver rows trigger on it).
    giver = cfg.stl.role.value == "giver"
    run = run_reach(controller, start, hand, duration, target=target, robot_holds_object=giver)
    tol = cfg.stl.eps_p_m if args.controller == "stl" else cfg.mcj.eps_x_m
    # What the controller goes to: the --target, unless an stl strategy goes towards the hand.
    to_target = target is not None and not (
        args.controller == "stl" and cfg.stl.strategy.towards_human
    )
    goal = target if to_target else None
    reached = run.reached_at(tol + 1e-6, goal)
    result = {
        "controller": args.controller,
        "feasible": run.feasible,
        "message": None if run.feasible else INFEASIBLE_MESSAGE,
        "first_infeasible_t": None
        if run.feasible
        else round(float(run.times[np.argmin(run.feasible_steps)]), 4),
        "reach_time_s": None if args.controller == "pv" else cfg.reach_time_s,
        "stall_time_s": cfg.stall_time_s if args.controller == "mce" else None,
        "goal": "target" if to_target else "hand",
        "reached_at_s": None if reached is None else round(float(reached), 4),
        "final_gap_m": round(float(run.gap(goal)[-1]), 5),
        "path": [
            [round(float(t), 4), *np.round(p, 5).tolist()]
            for t, p in zip(run.times, run.positions, strict=True)
        ],
        "solve_ms": round(float(np.median(run.solve_ms)), 3),
        "solve_ms_max": round(float(np.max(run.solve_ms)), 3),
        "control_period_ms": cfg.dt_s * 1e3,
    }
    if args.json:
        print(json.dumps(result))
    else:
        state = "feasible" if run.feasible else f"INFEASIBLE: {INFEASIBLE_MESSAGE}"
        arrival = "not reached" if reached is None else f"reached at {result['reached_at_s']:g} s"
        print(
            f"{args.controller}: {state}; {arrival}, "
            f"final gap {result['final_gap_m']} m; solve {result['solve_ms']} ms median "
            f"(max {result['solve_ms_max']}) per {result['control_period_ms']:.0f} ms step"
        )
    return 0


# ---------------------------------------------------------------------------- reach-table
def register_table(sub: argparse._SubParsersAction) -> None:
    """``gazebot reach-table``: the seed's Table 4.4 (module
    :mod:`gazebot.apps.controllers.reach_table`)."""
    p = sub.add_parser(
        "reach-table",
        help="the seed's Table 4.4: STL success rate over giving motions per t1 and u_max",
        description="Simulate the STL reach controller (eps_p 0.01 m, dt 0.2 s, H 20) on the "
        "reach phase of each giving motion and print the share it finds feasible per reach "
        "time and speed cap, beside the seed's Table 4.4.",
    )
    p.add_argument("--motions", type=int, default=70,
                   help="simulated giving motions (default 70, the seed's table's count)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the simulated motions")
    p.add_argument("--recording", type=Path, action="append", default=[],
                   help="a human-human recording to add (any format gazebot reads, e.g. a KTH "
                   "pose folder), repeatable")
    p.add_argument("--rate", type=float, help="sampling rate of pose-folder recordings, Hz")
    p.add_argument("--giver-hand", default="giver_RHand", help="recording: the giver's hand")
    p.add_argument("--receiver-hand", default="taker_RHand",
                   help="recording: the receiver's hand (where the robot's gripper starts)")
    p.add_argument("--receiver-base", default="taker_RShoulder",
                   help="recording: the receiver's point the robot's base stands at")
    p.add_argument("--config", type=Path,
                   help="controllers YAML (default: configs/controllers.yaml)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run_reach_table)


def run_reach_table(args: argparse.Namespace) -> int:
    from gazebot.apps.controllers.config import load_controllers_config
    from gazebot.apps.controllers.giving_motions import motion_from_recording
    from gazebot.apps.controllers.reach_table import table_4_4
    from gazebot.apps.sim.giving_motions import simulated_motions
    from gazebot.io.recordings import RecordingError

    if not 0 <= args.motions <= 1000:
        raise UsageError(f"--motions must be in [0, 1000], got {args.motions}")
    motions = simulated_motions(args.motions, args.seed)
    skipped = args.motions - len(motions)
    for path in args.recording:
        try:
            m = motion_from_recording(
                path, args.giver_hand, args.receiver_hand, args.receiver_base, args.rate
            )
        except RecordingError as exc:
            raise UsageError(str(exc)) from None
        if m is None:
            skipped += 1
        else:
            motions.append(m)
    if not motions:
        raise UsageError("no giving motion with a valid reach phase: give --motions or --recording")
    rows = table_4_4(motions, load_controllers_config(args.config))
    if args.json:
        print(json.dumps({
            "motions": len(motions),
            "skipped": skipped,
            "recordings": [str(p) for p in args.recording],
            "rows": [
                {"u_max_m_s": r.u_max_m_s, "t1_s": r.reach_time_s, "succeeded": r.succeeded,
                 "percent": round(r.percent, 1), "seed_percent": r.seed_percent}
                for r in rows
            ],
        }))
        return 0
    print(f"Table 4.4 over {len(motions)} giving motions ({skipped} without a valid reach phase "
          "skipped)")
    print(f"{'u_max (m/s)':>11}  {'t1 (s)':>6}  {'gazebot':>8}  {'seed':>6}")
    for r in rows:
        seed = "" if r.seed_percent is None else f"{r.seed_percent:.1f}%"
        print(f"{r.u_max_m_s:>11g}  {r.reach_time_s:>6g}  {r.percent:>7.1f}%  {seed:>6}")
    return 0
