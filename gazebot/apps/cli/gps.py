"""``gazebot gps``: the seed's chapter 5, Guided Policy Search (BADMM) for the reach, in MuJoCo.

  gazebot gps train --controllers 8|12 --trainer static|moving
      --state reduced|full|relative --out DIR
  gazebot gps train --add-controllers 4 --from DIR8 --out DIR12
  gazebot gps evaluate DIR --tester static|moving [--mass KG] [--grid N] [--json] [--plot PNG]
  gazebot gps demo DIR [--out VIDEO.mp4] [--tester static|moving] [--target X Y Z]
  gazebot gps figures LABEL=RESULT.npz... --out PNG
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from gazebot.apps.cli.argtypes import int_at_least, positive
from gazebot.apps.cli.errors import UsageError
from gazebot.apps.gps.tester import UnreachableTarget


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "gps",
        help="learn and evaluate the seed's GPS-BADMM reach (chapter 5) in MuJoCo",
        description="Guided Policy Search with BADMM (seed 5.2.1): a Panda learner reaches for a "
        "2-DoF tester's hand; train, evaluate on the semi-hemispherical shell (seed 5.4), plot.",
    )
    gsub = p.add_subparsers(dest="gps_command", metavar="SUBCOMMAND")
    gsub.required = True

    t = gsub.add_parser("train", help="train a global policy (writes DIR/policy.npz, meta.json)")
    t.add_argument("--controllers", type=int, choices=(8, 12), default=None,
                   help="local controllers: the shell's 8 corners (default), or 12 with its "
                   "middle plane, trained from scratch")
    t.add_argument("--trainer", choices=("static", "moving"), default=None,
                   help="the trainer holds its hand still (default) or reaches (eq. 5.12)")
    t.add_argument("--state", choices=("reduced", "full", "relative"), default=None,
                   help="state representation (eqs. 5.8-5.10; default reduced)")
    t.add_argument("--add-controllers", type=int, choices=(4,), default=None,
                   help="continue the 8-controller run --from DIR with the 4 local controllers "
                   "of the shell's middle plane added (the seed's 12-controller run)")
    t.add_argument("--from", dest="from_dir", default=None, metavar="DIR",
                   help="the trained run --add-controllers continues (its config, trainer and "
                   "state are kept)")
    t.add_argument("--iterations", type=int_at_least(1), default=None,
                   help="GPS iterations (default: the config's, the seed's 12)")
    t.add_argument("--config", default=None, help="GPS YAML (default: configs/gps.yaml)")
    t.add_argument("--out", required=True, help="output directory")
    t.add_argument("--quiet", action="store_true", help="no progress bar")
    t.set_defaults(func=_train)

    e = gsub.add_parser("evaluate", help="test a trained policy on the shell")
    e.add_argument("policy", help="directory written by `gazebot gps train`")
    e.add_argument("--tester", choices=("static", "moving"), default="static",
                   help="the tester holds its hand at each location or reaches it (eq. 5.12)")
    e.add_argument("--mass", type=positive, default=None,
                   help="end-effector mass in kg (default: the training's, 2 kg)")
    e.add_argument("--grid", type=int_at_least(2), default=None,
                   help="n x n test grid per azimuth (default 11: 2299 locations)")
    e.add_argument("--json", action="store_true", help="print the summary as JSON")
    e.add_argument("--save", default=None,
                   help="also write per-location results (.npz) and the summary (.json) here")
    e.add_argument("--plot", default=None, help="write the error-over-the-shell plot (Fig. 5.2)")
    e.add_argument("--quiet", action="store_true", help="no progress bar")
    e.set_defaults(func=_evaluate)

    d = gsub.add_parser("demo", help="render the learned reach to a video")
    d.add_argument("policy", help="directory written by `gazebot gps train`")
    d.add_argument("--out", default="out/gps-demo.mp4", help="output MP4")
    d.add_argument("--tester", choices=("static", "moving"), default="moving",
                   help="the tester holds its hand at the target or reaches it (eq. 5.12)")
    d.add_argument("--target", type=float, nargs=3, metavar=("X", "Y", "Z"), default=None,
                   help="the tester hand's final position, m in the learner's base frame "
                   "(default: the middle of the test shell)")
    d.add_argument("--json", action="store_true", help="print a JSON summary")
    d.set_defaults(func=_demo)

    f = gsub.add_parser("figures", help="plot Figs. 5.3-5.5 from saved evaluations")
    f.add_argument("results", nargs="+", help="LABEL=PATH.npz entries written by evaluate --save")
    f.add_argument("--kind", choices=("distributions", "mass"), default="distributions",
                   help="error distributions (Figs. 5.3, 5.5) or the mass sweep (Fig. 5.4)")
    f.add_argument("--out", required=True, help="output PNG")
    f.set_defaults(func=_figures)


def _train(args: argparse.Namespace) -> int:
    from gazebot.apps.gps.badmm import train
    from gazebot.apps.gps.config import load_gps_config
    from gazebot.apps.gps.policy_store import save
    from gazebot.apps.gps.state import StateKind

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out: {out} exists and is not a directory")
    if (args.add_controllers is None) != (args.from_dir is None):
        raise UsageError("--add-controllers and --from go together (continue a trained run)")
    start = time.monotonic()
    try:
        if args.from_dir is not None:
            result, cfg = _continue(args)
        else:
            cfg = load_gps_config(args.config)
            result = train(cfg, args.controllers or 8, args.trainer == "moving",
                           StateKind(args.state or "reduced"), iterations=args.iterations,
                           progress=not args.quiet)
    except UnreachableTarget as exc:
        raise UsageError(f"the configuration's shell is out of the tester's reach: {exc}") from exc
    seconds = time.monotonic() - start
    save(result, cfg, out, seconds)
    print(json.dumps({"out": str(out), "train_error_m": float(result.train_errors_m.mean()),
                      "seconds": round(seconds, 1)}))
    return 0


def _continue(args: argparse.Namespace):
    """``--add-controllers 4 --from DIR``: the 8-controller run in DIR continued with the 4
    middle-plane controllers (its config, trainer and state representation kept)."""
    import numpy as np

    from gazebot.apps.gps.badmm import continue_training
    from gazebot.apps.gps.policy_store import load_checkpoint
    from gazebot.apps.gps.shell import training_targets

    for option, value in (("--controllers", args.controllers), ("--config", args.config)):
        if value is not None:
            raise UsageError(f"{option} does not go with --from: the run's own is kept")
    if Path(args.from_dir).resolve() == Path(args.out).resolve():
        raise UsageError("--out must differ from --from (the 8-controller run stays as it was)")
    previous, cfg = load_checkpoint(args.from_dir)
    for option, value, kept in (("--trainer", args.trainer,
                                 "moving" if previous.moving else "static"),
                                ("--state", args.state, previous.kind.value)):
        if value is not None and value != kept:
            raise UsageError(f"{option} {value}: the run in {args.from_dir} was trained with "
                             f"{kept}, which continuing keeps")
    twelve = training_targets(cfg.shell, 12)
    if len(previous.targets) != 8 or not np.allclose(previous.targets, twelve[:8]):
        raise UsageError(f"--from {args.from_dir}: expected a run of the shell's 8 corner "
                         f"controllers, got {len(previous.targets)} controllers")
    return continue_training(cfg, previous, twelve[8:], iterations=args.iterations,
                             progress=not args.quiet), cfg


def _evaluate(args: argparse.Namespace) -> int:
    from gazebot.apps.gps.evaluate import evaluate
    from gazebot.apps.gps.policy_store import load

    trained = load(args.policy)
    try:
        ev = evaluate(trained, args.tester == "moving", args.mass, args.grid,
                      progress=not args.quiet)
    except UnreachableTarget as exc:
        raise UsageError(f"the policy's shell is out of the tester's reach: {exc}") from exc
    summary = ev.summary()
    if args.save:
        # Append the suffixes: a stem like "run_m0.5" must not lose its ".5".
        base = Path(args.save)
        stem = base.stem if base.suffix in (".npz", ".json") else base.name
        base.parent.mkdir(parents=True, exist_ok=True)
        ev.save(base.parent / f"{stem}.npz")
        (base.parent / f"{stem}.json").write_text(json.dumps(summary, indent=2) + "\n",
                                                  encoding="utf-8")
    if args.plot:
        from gazebot.apps.gps.plots import shell_plot

        shell_plot(ev, trained, Path(args.plot))
    if args.json:
        print(json.dumps(summary))
    else:
        for k, v in summary.items():
            print(f"{k}: {v:.4f}" if isinstance(v, float) else f"{k}: {v}")
    sys.stdout.flush()
    return 0


def _demo(args: argparse.Namespace) -> int:
    from gazebot.apps.render.gl_check import ensure_gl_backend

    ensure_gl_backend()  # before MuJoCo loads: off-screen EGL or OSMesa
    from gazebot.apps.gps.demo import run_demo

    try:
        res = run_demo(args.policy, args.out, args.tester == "moving", args.target)
    except UnreachableTarget as exc:
        raise UsageError(f"--target: {exc}") from exc
    summary = {"video": str(res.video), "frames": res.frames, "target_m": res.target_m,
               "error_m": res.error_m}
    print(json.dumps(summary) if args.json else f"wrote {res.video} (error {res.error_m:.3f} m)")
    return 0


def _figures(args: argparse.Namespace) -> int:
    from gazebot.apps.gps.plots import distributions_plot, load_results, mass_plot

    entries = []
    for item in args.results:
        label, sep, path = item.partition("=")
        if not sep or not label or not path:
            raise UsageError(f"results: expected LABEL=PATH.npz, got {item!r}")
        entries.append((label, Path(path)))
    results = load_results(entries)
    if args.kind == "mass":
        mass_plot(results, Path(args.out))
    else:
        distributions_plot(results, Path(args.out))
    print(args.out)
    return 0
