"""``gazebot bip``: the seed's 7.4-7.5, Bayesian Interaction Primitives for a robot giver's
two-handed reach, with the grip-width constraint.

  gazebot bip demos --synthetic N --seed S [--widths W ...] --out FOLDER
  gazebot bip train (DEMOS | --synthetic N --seed S) --out DIR
  gazebot bip evaluate DIR --test DEMOS [--observe N] [--constraint MODE] [--json]
  gazebot bip figure DIR --test DEMOS [--observe N] --out FIG.png
  gazebot bip scene DIR --test DEMOS [--constraint MODE] --out FOLDER

DEMOS is a folder of demonstration CSVs (or one CSV); widths in m.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from gazebot.apps.cli.argtypes import int_at_least, positive, seed_value
from gazebot.apps.cli.errors import UsageError

MODES = ("none", "projection", "filter")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "bip",
        help="Bayesian Interaction Primitives for a two-handed robot reach (seed 7.4-7.5)",
        description="Bayesian Interaction Primitives (seed 7.4) for a robot giver's two-handed "
        "reach, with the grip-width constraint of 7.5 imposed by projecting the prior "
        "(projection) or inside the ensemble filter (filter).",
    )
    bsub = p.add_subparsers(dest="bip_command", metavar="SUBCOMMAND")
    bsub.required = True

    d = bsub.add_parser("demos", help="write synthetic two-handed handover demonstrations (CSV)")
    _synthetic_args(d, required=True)
    d.add_argument("--out", required=True, help="output folder")
    d.set_defaults(func=_demos)

    t = bsub.add_parser("train", help="fit the BIP prior (writes DIR/bip_prior.npz, .json)")
    t.add_argument("demos", nargs="?", default=None, help="folder of demonstration CSVs")
    _synthetic_args(t, required=False)
    t.add_argument("--basis", type=int_at_least(2), default=9,
                   help="radial basis functions per degree of freedom (default 9)")
    t.add_argument("--out", required=True, help="output directory")
    t.set_defaults(func=_train)

    for name, helptext, func in (
        ("evaluate", "prediction errors on held-out demonstrations", _evaluate),
        ("figure", "plot like seed Figs. 7.9-7.10", _figure),
        ("scene", "robot-giver scene with the gaze engine (timeline CSV and plot)", _scene),
    ):
        e = bsub.add_parser(name, help=helptext)
        e.add_argument("model", help="directory written by `gazebot bip train`")
        e.add_argument("--test", required=True, help="folder of test demonstration CSVs (or one)")
        e.add_argument("--observe", type=int_at_least(1), default=10,
                       help="samples observed before predicting (default 10, as in seed 7.4.2)")
        e.add_argument("--members", type=int_at_least(2), default=100,
                       help="ensemble members (default 100)")
        e.add_argument("--seed", type=seed_value, default=0, help="random seed (default 0)")
        e.add_argument("--observe-width", action="store_true",
                       help="also observe the grip-width degree of freedom (default: only the "
                       "receiver's wrists are observed)")
        if name == "evaluate":
            e.add_argument("--constraint", choices=MODES, action="append", default=None,
                           help="constraint mode(s) (repeatable; default: all three)")
            e.add_argument("--json", action="store_true", help="print JSON")
            e.add_argument("--per-test", action="store_true", help="JSON: keep per-test rows")
        elif name == "figure":
            e.add_argument("--index", type=int_at_least(0), default=0,
                           help="which test demonstration to plot (default the first)")
            e.add_argument("--out", required=True, help="output PNG")
        else:
            e.add_argument("--constraint", choices=MODES, default="filter",
                           help="constraint mode (default filter)")
            e.add_argument("--index", type=int_at_least(0), default=0,
                           help="which test demonstration to play (default the first)")
            e.add_argument("--out", required=True, help="output folder")
        e.set_defaults(func=func)


def _synthetic_args(p: argparse.ArgumentParser, required: bool) -> None:
    p.add_argument("--synthetic", type=int_at_least(2), default=None, required=required,
                   metavar="N", help="generate N demonstrations (gazebot.apps.bip.demos)")
    p.add_argument("--seed", type=seed_value, default=0, help="generator seed (default 0)")
    p.add_argument("--widths", type=positive, nargs="+", default=None, metavar="W",
                   help="grip widths (m), cycled over the demonstrations (default: uniform "
                   "0.22-0.42 m)")


def _demos(args: argparse.Namespace) -> int:
    from gazebot.apps.bip.demos import DemoGenerator, save_demos

    demos = DemoGenerator().draw_many(args.synthetic, args.seed, args.widths)
    paths = save_demos(demos, args.out)
    print(json.dumps({"out": str(args.out), "demonstrations": len(paths),
                      "widths_m": [round(d.width, 4) for d in demos]}))
    return 0


def _train(args: argparse.Namespace) -> int:
    from gazebot.apps.bip.basis import GaussianBasis
    from gazebot.apps.bip.demos import DemoGenerator, load_demos, save_demos
    from gazebot.apps.bip.prior import TrainConfig, train

    if (args.demos is None) == (args.synthetic is None):
        raise UsageError("give either a DEMOS folder or --synthetic N")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out: {out} exists and is not a directory")
    if args.demos is not None:
        demos = load_demos(args.demos)
        if len(demos) < 2:
            raise UsageError(f"{args.demos}: a BIP prior needs at least 2 demonstrations")
    else:
        demos = DemoGenerator().draw_many(args.synthetic, args.seed, args.widths)
        save_demos(demos, out / "demos")
    prior = train(demos, TrainConfig(basis=GaussianBasis.spaced(args.basis)))
    prior.save(out)
    print(json.dumps({"out": str(out), "demonstrations": len(demos),
                      "width_mean_m": round(prior.width_mean, 4),
                      "state_dim": int(prior.mean.size)}))
    return 0


def _load(args: argparse.Namespace):
    from gazebot.apps.bip.demos import RECEIVER_DOFS, WIDTH_DOF, load_demos
    from gazebot.apps.bip.enbip import FilterConfig
    from gazebot.apps.bip.prior import BipPrior

    prior = BipPrior.load(args.model)
    tests = load_demos(args.test)
    short = [d.name for d in tests if d.t.size <= args.observe]
    if short:
        raise UsageError(f"--observe {args.observe}: not shorter than test(s) {', '.join(short)}")
    observed = RECEIVER_DOFS + ((WIDTH_DOF,) if args.observe_width else ())
    return prior, tests, FilterConfig(members=args.members, observed=observed)


def _pick(tests: list, index: int, what: str):
    if index >= len(tests):
        raise UsageError(f"--index {index}: {what} has {len(tests)} demonstration(s)")
    return tests[index]


def _evaluate(args: argparse.Namespace) -> int:
    from gazebot.apps.bip.evaluate import evaluate

    prior, tests, cfg = _load(args)
    modes = tuple(dict.fromkeys(args.constraint)) if args.constraint else MODES
    result = evaluate(prior, tests, args.observe, modes, cfg, args.seed)
    if not args.per_test:
        for v in result["modes"].values():
            v.pop("tests")
    if args.json:
        print(json.dumps(result))
        return 0
    print(f"observe {args.observe} samples, {len(tests)} tests, training mean width "
          f"{result['training_width_mean_m']:.3f} m")
    for mode, v in result["modes"].items():
        print(f"{mode:>10}: grip width error mean {v['width_error_mean_m'] * 100:.2f} cm, "
              f"max {v['width_error_max_m'] * 100:.2f} cm; wrist error "
              f"{v['position_error_m'] * 100:.2f} cm (x{v.get('position_error_vs_none', 1):.2f} "
              f"of none); width error / deviation {v['width_error_over_deviation']:.2f}")
    return 0


def _figure(args: argparse.Namespace) -> int:
    from gazebot.apps.bip.evaluate import predict_test
    from gazebot.apps.bip.plots import bip_figure

    prior, tests, cfg = _load(args)
    test = _pick(tests, args.index, args.test)
    preds = {m: predict_test(prior, test, args.observe, m, cfg, args.seed) for m in MODES}
    path = bip_figure(prior, test, preds, args.out)
    print(json.dumps({"figure": str(path), "test": test.name, "width_m": test.width}))
    return 0


def _scene(args: argparse.Namespace) -> int:
    from gazebot.apps.bip.scene import run_scene, write_scene

    prior, tests, cfg = _load(args)
    test = _pick(tests, args.index, args.test)
    run = run_scene(prior, test, args.constraint, filter_config=cfg, seed=args.seed)
    print(json.dumps(write_scene(run, args.out)))
    return 0
