"""``gazebot study plan|render|serve|export|analyze|fit-wins``: run a pairwise video study end to
end."""

from __future__ import annotations

import argparse
import functools
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path

from gazebot.apps.cli.argtypes import seed_value
from gazebot.apps.cli.errors import UsageError
from gazebot.apps.render.video_settings import VIDEO
from gazebot.apps.study.conditions import (
    CONDITION_LEVELS,
    DEFAULT_BEHAVIORS,
    GAZE_MODES,
    REACH_BEHAVIORS,
    default_behaviors,
)
from gazebot.core.config import ConfigError


def _input_errors(command: Callable[[argparse.Namespace], int]) -> Callable:
    """The study package raises ``ValueError`` (naming file, line and field) for bad input files
    and options: report those as the command line's input errors (:class:`UsageError`), not as
    bugs."""

    @functools.wraps(command)
    def run(args: argparse.Namespace) -> int:
        try:
            return command(args)
        except (ConfigError, UsageError):
            raise
        except ValueError as exc:
            raise UsageError(str(exc)) from exc

    return run


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser("study", help="plan, render and analyze a pairwise gaze video study")
    study = parser.add_subparsers(dest="study_command", metavar="STUDY_COMMAND")
    study.required = True

    p = study.add_parser("plan", help="write a counterbalanced session plan (CSV)")
    p.add_argument(
        "--behaviors",
        default=None,
        help="comma-separated behavior names (default: the seed's: "
        f"{','.join(REACH_BEHAVIORS)} without a condition (6.3), "
        f"{','.join(DEFAULT_BEHAVIORS)} with one (6.4))",
    )
    p.add_argument(
        "--condition",
        default=None,
        choices=list(CONDITION_LEVELS),
        help="none: every ordered pair once (6.3); else both levels of it (6.4): "
        + "; ".join(f"{c}: {a} / {b}" for c, (a, b) in CONDITION_LEVELS.items()),
    )
    p.add_argument(
        "--participants",
        type=int,
        required=True,
        help="a multiple of the block size: g*(g-1) without a condition, 2*g*(g-1) with one",
    )
    p.add_argument(
        "--gaze-mode",
        choices=list(GAZE_MODES),
        default=None,
        help="how the robot shows its gaze (default: the seed's: head-only without a condition, "
        "eyes-only with one); the instructions name the head or the eyes to match",
    )
    p.add_argument("--seed", type=seed_value, default=0, help="randomisation seed")
    p.add_argument(
        "--robot",
        default=None,
        help="robot config (default: the seed's: jaco2, the Jaco-2 with its head, without a "
        "condition (6.3); sawyer with one (6.4))",
    )
    p.add_argument(
        "--video-seed", type=seed_value, default=0, help="seed of every rendered handover"
    )
    p.add_argument(
        "--scene",
        action="append",
        default=[],
        metavar="LEVEL=SCENE",
        help="render a level in another scene (default: the shipped scene of the level); "
        "without a condition just SCENE (default: robot-initiated)",
    )
    p.add_argument(
        "--out", type=Path, default=Path("plan.csv"), help="plan CSV file (default: plan.csv)"
    )
    p.add_argument("--json", action="store_true", help="print the balance summary as JSON")
    p.set_defaults(func=_input_errors(_plan))

    r = study.add_parser("render", help="render a plan's videos, pair videos and questionnaires")
    r.add_argument("plan", type=Path, help="plan CSV written by `gazebot study plan`")
    r.add_argument(
        "--out",
        required=True,
        type=Path,
        help="study folder to write (videos/, pairs/, participants/, manifest.json; reused "
        "videos come from its cache)",
    )
    r.add_argument("--width", type=int, default=VIDEO.width,
                        help=f"video width, px (default: {VIDEO.width})")
    r.add_argument("--height", type=int, default=VIDEO.height,
                        help=f"video height, px (default: {VIDEO.height})")
    r.add_argument("--fps", type=int, default=30, help="frames per second (default: 30)")
    r.add_argument("--workers", type=int, default=None, help="processes (default: CPU cores)")
    r.add_argument("--card-seconds", type=float, default=1.5, help="title card duration (s)")
    r.add_argument(
        "--renderer",
        choices=["mujoco", "synthetic"],
        default="mujoco",
        help="synthetic: labelled flat clips for a quick dry run",
    )
    r.add_argument(
        "--code-version",
        default=None,
        help="pin the cache key's code version (default: a hash of gazebot's sources and configs)",
    )
    r.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    r.set_defaults(func=_input_errors(_render))

    sv = study.add_parser("serve", help="run a rendered study in the browser (answers in SQLite)")
    sv.add_argument("dir", type=Path, help="a folder written by `gazebot study render`")
    sv.add_argument("--host", default="127.0.0.1", help="address to listen on")
    sv.add_argument("--port", type=int, default=8000, help="port (0: any free port)")
    sv.add_argument("--threads", type=int, default=4, help="server worker threads")
    sv.add_argument(
        "--admin-token-file",
        type=Path,
        default=None,
        metavar="FILE",
        help="file holding the token that opens /admin (default: the "
        "environment variable GAZEBOT_STUDY_ADMIN_TOKEN, else a random token written to "
        "DIR/admin-token); never on the command line, where ps shows it",
    )
    sv.add_argument(
        "--local-admin",
        action="store_true",
        help="open /admin without the token to requests from loopback (anyone on this machine; "
        "never behind a reverse proxy on it)",
    )
    sv.add_argument(
        "--allowed-host",
        action="append",
        default=[],
        metavar="NAME",
        help="a host name browsers use for this server besides localhost and the --host name "
        "(repeatable; e.g. a reverse proxy's name); other names get 400 (DNS rebinding)",
    )
    sv.set_defaults(func=_input_errors(_serve))

    ex = study.add_parser("export", help="write the answers of a served study as a responses CSV")
    ex.add_argument("dir", type=Path, help="a study folder served by `gazebot study serve`")
    ex.add_argument("--out", required=True, type=Path, help="CSV file for `gazebot study analyze`")
    ex.add_argument(
        "--include-practice",
        action="store_true",
        help="also the practice session (session 0; for inspection, not for analyze)",
    )
    ex.set_defaults(func=_input_errors(_export))

    a = study.add_parser("analyze", help="Bradley-Terry analysis of a responses CSV")
    a.add_argument(
        "responses", type=Path, help="responses CSV (from `gazebot study export`, or by hand)"
    )
    a.add_argument("--json", action="store_true", help="print one JSON document")
    a.add_argument(
        "--plot",
        type=Path,
        default=None,
        help="PNG like the seed's Figure 6.3 (one file per level if several)",
    )
    a.add_argument(
        "--margin", type=float, default=0.1, help="equivalence margin (proportion in (0, 1))"
    )
    a.add_argument(
        "--behaviors", default=None, help="comma-separated order of the behaviors in the output"
    )
    a.add_argument(
        "--bias-unit",
        choices=["participant", "session"],
        default="participant",
        help="one value per participant (default) or per session (like the seed) in the bias test",
    )
    a.add_argument(
        "--sides",
        choices=["one", "two"],
        default=None,
        help="override the sidedness of every proportion difference test (default: as the "
        "seed's tables, matched one-sided in the observed direction as B.7-B.9, unmatched "
        "video vs in-person two-sided as B.10-B.12)",
    )
    a.set_defaults(func=_input_errors(_analyze))

    f = study.add_parser("fit-wins", help="Bradley-Terry fit of a win-count matrix CSV")
    f.add_argument(
        "wins",
        type=Path,
        help="CSV matrix: conditions in the header row and first column, cell (i, j) = wins "
        "of i over j",
    )
    f.add_argument(
        "--participants",
        type=float,
        required=True,
        help="n: every pair compared n times (cell(i,j) + cell(j,i) = n); a pair with another "
        "total is fitted with its own total, with a warning",
    )
    f.add_argument("--json", action="store_true", help="print one JSON document")
    f.set_defaults(func=_input_errors(_fit_wins))
    _register_analyses(study)


def _finite(value: float, option: str, low: float = 0.0, high: float = math.inf) -> float:
    """``value`` if finite and in (low, high); ``UsageError`` naming ``option`` otherwise."""
    if not (math.isfinite(value) and low < value < high):
        bound = f"in ({low:g}, {high:g})" if math.isfinite(high) else f"> {low:g}"
        raise UsageError(f"{option} must be a finite number {bound}, got {value}")
    return value


def _check_behaviors(names: list[str]) -> None:
    """Every name must be an available behavior (see ``gazebot behaviors list``)."""
    from gazebot.core.behaviors import list_behaviors, load_behavior

    for name in names:
        try:
            load_behavior(name)
        except FileNotFoundError:
            available = ", ".join(i.name for i in list_behaviors())
            raise UsageError(
                f"--behaviors: unknown behavior {name!r}; available: {available}"
            ) from None


def _check_robot(name: str | None) -> None:
    """``--robot`` must name a robot config (or a robot YAML file): fail at plan time, not an
    hour into rendering."""
    if name is None:
        return
    from gazebot.core.kinematics.robot_config import robot_config_path

    try:
        robot_config_path(name)
    except FileNotFoundError as exc:
        raise UsageError(f"--robot: {exc}") from None


def _plan(args: argparse.Namespace) -> int:
    from gazebot.apps.study.csvio import check_output_file
    from gazebot.apps.study.plan import check_balance, make_plan, write_plan

    check_output_file(args.out, "plan")
    names = (
        args.behaviors
        if args.behaviors is not None
        else ",".join(default_behaviors(args.condition))
    )
    behaviors = [b.strip() for b in names.split(",") if b.strip()]
    _check_behaviors(behaviors)
    _check_robot(args.robot)
    scenes = {}
    for item in args.scene:
        level, sep, scene = item.partition("=")
        if not sep and not args.condition and level:
            scenes[""] = level  # no condition: the single scenario's scene
            continue
        if not sep or not level or not scene:
            raise UsageError(f"--scene expects LEVEL=SCENE, got {item!r}")
        scenes[level] = scene
    plan = make_plan(
        behaviors,
        args.condition,
        args.participants,
        args.seed,
        args.robot,
        scenes,
        args.video_seed,
        args.gaze_mode,
    )
    write_plan(plan, args.out)
    report = check_balance(plan)
    summary = {
        "out": str(args.out),
        "participants": args.participants,
        "sessions_per_participant": len(plan) // args.participants,
        "behaviors": behaviors,
        "condition": args.condition or "",
        "robot": plan[0].robot,
        "gaze_mode": plan[0].gaze_mode,
        "position_balanced": report.position_balanced,
        "carryover_balanced": report.carryover_balanced,
    }
    if args.json:
        print(json.dumps(summary))
    else:
        print(
            f"wrote {len(plan)} sessions ({len(plan) // args.participants} per participant) for "
            f"{args.participants} participants to {args.out} (robot {plan[0].robot}, gaze mode "
            f"{plan[0].gaze_mode}, "
            f"position balanced: {report.position_balanced}, "
            f"carry-over balanced: {report.carryover_balanced})"
        )
    return 0


def _render(args: argparse.Namespace) -> int:
    import os

    os.environ.setdefault("MUJOCO_GL", "egl")  # off-screen rendering in every worker
    from gazebot.apps.study.plan import read_plan
    from gazebot.apps.study.render import default_renderer, render_study
    from gazebot.apps.study.synthetic import render_synthetic_video

    plan = read_plan(args.plan)
    if args.renderer == "synthetic":
        fn = render_synthetic_video
    else:
        from gazebot.core.config import configs_dir

        # Fail before starting workers: an unknown scene would only surface inside a worker.
        for scene in sorted({s.scene for s in plan}):
            if not (configs_dir() / "scenes" / f"{scene}.yaml").is_file() and not (
                scene.endswith((".yaml", ".yml")) and Path(scene).is_file()
            ):
                raise UsageError(
                    f"{args.plan}: unknown scene {scene!r} (no configs/scenes/{scene}.yaml)"
                )
        fn = default_renderer()
    rep = render_study(
        plan,
        args.out,
        fn,
        args.width,
        args.height,
        args.fps,
        args.workers,
        args.card_seconds,
        code_version_str=args.code_version,
        progress=not args.no_progress,
    )
    print(
        f"{len(rep.videos)} handover videos ({len(rep.rendered)} rendered, "
        f"{len(rep.videos) - len(rep.rendered)} cached), {len(rep.pairs)} pair videos, "
        f"{sum(len(v) for v in rep.sessions.values())} session files, video times in "
        f"{Path(args.out) / 'videos.csv'}; "
        f"response sheet {rep.questionnaire_csv}"
    )
    return 0


def _analyze(args: argparse.Namespace) -> int:
    from gazebot.apps.study.analysis import analyze, read_responses

    _finite(args.margin, "--margin", 0.0, 1.0)
    if args.plot is not None:
        from gazebot.apps.study.csvio import check_output_file

        check_output_file(args.plot, "plot", ".png")
    order = [b.strip() for b in args.behaviors.split(",")] if args.behaviors else None
    result = analyze(
        read_responses(args.responses),
        margin=args.margin,
        behaviors=order,
        bias_unit=args.bias_unit,
        sides=args.sides,
    )
    if args.plot is not None:
        from gazebot.apps.study.plots import plot_preferences

        for level, measures in result.per_level.items():
            out = args.plot
            if len(result.per_level) > 1:
                tag = (level or "all").replace(":", "-")
                out = args.plot.with_name(f"{args.plot.stem}-{tag}{args.plot.suffix}")
            plot_preferences(measures, out, title=level)
    if args.json:
        print(json.dumps(result.to_json()))
        return 0
    for level, measures in result.per_level.items():
        print(f"## level: {level or '(single scenario)'}")
        for m, r in measures.items():
            ps = ", ".join(f"{c}={v:.2f}" for c, v in r.fit.as_dict().items())
            print(
                f"  {m}: P_i {ps}; chi2={r.chi2.chi2:.2f} df={r.chi2.df} "
                f"p={r.chi2.p_value:.3g} (n={r.participants})"
            )
    for m, b in result.bias.items():
        print(f"first/second bias {m}: S={b.s:.1f} p={b.p_value:.2f}")
    for q, b in result.bias_per_question.items():
        # The seed quotes z with its normal p (6.4.4: "like: z = -0.68, p = 0.50").
        print(f"first/second bias {q}: S={b.s:.1f} z={b.z:.2f} p={b.p_z:.2f}")
    for g, tests in result.bias_by_group.items():
        for k, b in tests.items():
            p = b.p_z if k.startswith("q") else b.p_value
            print(f"first/second bias, group {g}, {k}: S={b.s:.1f} z={b.z:.2f} p={p:.2f}")
    for c in result.comparisons:
        print(
            f"{c.measure} {c.behavior_i} vs {c.behavior_j} ({c.design}, n={c.n_a}/{c.n_b}): "
            f"{c.sample_a} {c.proportion_a:.2f} vs {c.sample_b} {c.proportion_b:.2f}, "
            f"z={c.difference.z:.2f} p={c.difference.p_value:.2f} ({c.sides}-sided"
            f"{', as ' + c.table if c.table and args.sides is None else ''}), "
            f"equivalence p={c.equivalence.p_value:.2f}"
        )
    return 0


def _fit_wins(args: argparse.Namespace) -> int:
    import numpy as np

    from gazebot.apps.study.analysis import read_win_matrix
    from gazebot.apps.study.bradley_terry import fit_bradley_terry
    from gazebot.apps.study.stats import bradley_terry_chi2, likelihood_ratio_chi2

    n = _finite(args.participants, "--participants")
    names, w = read_win_matrix(args.wins)
    totals = w + w.T
    iu = np.triu_indices(len(names), k=1)
    bad = [
        (names[i], names[j], totals[i, j])
        for i, j in zip(*iu, strict=True)
        if abs(totals[i, j] - n) > 1e-6 * max(1.0, n)
    ]
    fit = fit_bradley_terry(w, names)
    if bad:
        # A published table may have a pair not every participant answered (the seed's Table
        # B.3: 23 of 24). The MM fit uses each pair's own total already; the chi-square of
        # eq. 6.2 assumes n per pair, so the likelihood-ratio form (equal to it for n) is used.
        for i, j, t in bad:
            print(
                f"gazebot: warning: {args.wins}: cells ({i}, {j}) + ({j}, {i}) = {t:g}, not "
                f"--participants {n:g}; using that pair's own total",
                file=sys.stderr,
            )
        chi = likelihood_ratio_chi2(w, fit.p)
    else:
        chi = bradley_terry_chi2(fit.wins, fit.p, n)
    out = {
        "conditions": names,
        "p": [float(v) for v in fit.p],
        "chi2": chi.chi2,
        "df": chi.df,
        "p_value": chi.p_value,
        "pair_totals_differ": [[i, j, t] for i, j, t in bad],
    }
    if args.json:
        print(json.dumps(out))
    else:
        for c, v, a in zip(names, fit.p, fit.wins, strict=True):
            print(f"{c}: a_i={a:g} P_i={v:.2f}")
        print(f"chi2={chi.chi2:.3f} df={chi.df} p={chi.p_value:.3g}")
    return 0


def _serve(args: argparse.Namespace) -> int:
    from gazebot.apps.study.web.server import serve

    if not 0 <= args.port <= 65535:
        raise UsageError(f"--port must be in 0..65535, got {args.port}")
    if args.threads < 1:
        raise UsageError(f"--threads must be >= 1, got {args.threads}")
    serve(
        str(args.dir),
        args.host,
        args.port,
        args.threads,
        args.admin_token_file,
        local_admin=args.local_admin,
        allowed_hosts=tuple(args.allowed_host),
    )
    return 0


def _export(args: argparse.Namespace) -> int:
    from gazebot.apps.study.export import export_responses, participants_file
    from gazebot.apps.study.study_file import STUDY_FILE

    out, n = export_responses(args.dir, args.out, args.include_practice)
    print(f"wrote {n} answered sessions to {out}")
    if (args.dir / STUDY_FILE).is_file():  # a study file's study: its per-participant answers
        print(f"wrote each participant's answers to {participants_file(out)}")
    return 0


# ------------------------------------------------------- in-person and chapter 3 analyses
def _register_analyses(study: argparse._SubParsersAction) -> None:
    ip = study.add_parser(
        "in-person",
        help="in-person study: ANOVA of reach-start time over gaze conditions, familiarity",
        description="One-way ANOVA of the giver's reach-start time across the gaze conditions "
        "and the familiarity question's mean and SD (seed 6.3.3, 6.4.5), from a responses CSV.",
    )
    ip.add_argument("responses", type=Path, help="responses CSV (`gazebot study export`)")
    ip.add_argument("--json", action="store_true", help="print one JSON document")
    ip.set_defaults(func=_input_errors(_in_person))
    ms = study.add_parser(
        "measures",
        help="UEQ scales, NASA TLX items and their Pearson correlations (seed ch. 3, App. A)",
        description="Score a questionnaire CSV: UEQ scale means, NASA TLX item means and the "
        "Pearson correlations of the seed's Appendix A, per controller and round.",
    )
    ms.add_argument("questionnaire", type=Path, help="questionnaire CSV (ueq1..ueq26, tlx_*)")
    ms.add_argument("--json", action="store_true", help="print one JSON document")
    ms.set_defaults(func=_input_errors(_measures))


def _in_person(args: argparse.Namespace) -> int:
    from gazebot.apps.study.in_person import (
        familiarity_summary,
        reach_start_anova,
        read_in_person,
    )

    data = read_in_person(args.responses)
    anova = reach_start_anova(data.reach_start) if data.reach_start else None
    fam = familiarity_summary(data.familiarity) if data.familiarity else None
    if anova is None and fam is None:
        raise UsageError(
            f"{args.responses}: no in-person reach-start times and no familiarity answers "
            "(columns first_reach_start_time, second_reach_start_time, familiarity)"
        )
    if args.json:
        print(json.dumps({
            "reach_start_anova": anova.to_json() if anova else None,
            "familiarity": fam.to_json() if fam else None,
        }))
        return 0
    if anova is not None:
        print(f"reach-start time, one-way ANOVA over {len(anova.groups)} gaze conditions: "
              f"F({anova.df_between}, {anova.df_within}) = {anova.f:.3f}, p = {anova.p:.3f}")
        for k, v in anova.groups.items():
            print(f"  {k}: mean {sum(v) / len(v):.3f} s (n={len(v)})")
    if fam is not None:
        print(f"familiarity (1-5): M = {fam.mean:.2f}, SD = {fam.sd:.2f} (n={fam.n})")
    return 0


def _measures(args: argparse.Namespace) -> int:
    from gazebot.apps.study.measures import analyze_measures, read_questionnaire

    result = analyze_measures(read_questionnaire(args.questionnaire))
    doc = result.to_json()
    if args.json:
        print(json.dumps(doc))
        return 0
    for group, parts in doc.items():
        print(f"## {group}")
        for s, v in parts["ueq"].items():
            print(f"  UEQ {s}: M = {v['M']:.2f} (1-7: {v['M'] + 4:.2f}), SD = {v['SD']:.2f} "
                  f"(n={v['n']})")
        for t, v in parts["tlx"].items():
            print(f"  TLX {t}: M = {v['M']:.2f}, SD = {v['SD']:.2f} (n={v['n']})")
        for c in parts["pearson"]:
            print(f"  r({c['tlx']}, {c['ue']}) = {c['r']:.3f}, p = {c['p']:.3f}")
    return 0
