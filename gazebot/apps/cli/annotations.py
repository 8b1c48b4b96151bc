"""``gazebot annotations``: human gaze patterns in the annotated handovers, replay, model fit."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from gazebot.apps.cli.argtypes import seed_value
from gazebot.apps.cli.choices import add_behavior_argument


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser("annotations", help="analyse the human-human gaze annotations")
    cmds = parser.add_subparsers(dest="annotations_command", metavar="ACTION")
    cmds.required = True

    p = cmds.add_parser(
        "summarize", help="reach and three-phase gaze patterns beside the seed's published shares"
    )
    p.add_argument("dir", type=Path, help="folder of the annotations (handover-gaze-annotations)")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument("--plot", type=Path, metavar="FILE.png", help="save bar charts to this file")
    p.set_defaults(func=_summarize)

    p = cmds.add_parser(
        "replay", help="share of frames where a behavior's target matches the person's gaze"
    )
    p.add_argument("dir", type=Path, help="folder of the annotations")
    add_behavior_argument(p, action="append", required=True,
                          what="behavior to replay, repeatable ('all': every one)")
    p.add_argument(
        "--role",
        choices=("receiver", "giver"),
        default="receiver",
        help="whose gaze: the receiver's (default, the robot's part) or the giver's",
    )
    p.add_argument("--seed", type=seed_value, default=0, help="seed of data-driven behaviors")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.set_defaults(func=_replay)

    p = cmds.add_parser(
        "fit-human", help="fit the data-driven behavior (patterns and shift timings) to a role"
    )
    p.add_argument("dir", type=Path, help="folder of the annotations")
    p.add_argument(
        "--role",
        choices=("receiver", "giver"),
        default="receiver",
        help="whose gaze: the receiver's (default, the robot's part) or the giver's",
    )
    p.add_argument("--min-count", type=int, default=3, help="keep patterns seen this often")
    p.add_argument("-o", "--output", type=Path, help="write the behavior YAML here")
    p.set_defaults(func=_fit)


def _summarize(args: argparse.Namespace) -> int:
    from gazebot.apps.annotations import load_annotations, plot_summary, summarize
    from gazebot.apps.annotations.summary import check_png_path

    if args.plot:
        check_png_path(args.plot)  # before the slow load: a folder or .jpg is a usage error
    summary = summarize(load_annotations(args.dir))
    if args.plot:
        plot_summary(summary, args.plot)
    if args.json:
        print(json.dumps(summary.to_json(), indent=2))
    else:
        print(summary.format())
        if args.plot:
            print(f"\nplot: {args.plot}")
    return 0


def _replay(args: argparse.Namespace) -> int:
    from gazebot.apps.annotations import load_annotations, replay
    from gazebot.core.behaviors import list_behaviors, load_behavior

    names: list[str] = []
    for name in args.behavior:
        names += [i.name for i in list_behaviors()] if name == "all" else [name]
    specs = [load_behavior(n) for n in dict.fromkeys(names)]
    annotations = load_annotations(args.dir)
    results = [replay(annotations, s, args.role, seed=args.seed) for s in specs]
    results.sort(key=lambda r: -r.share)
    if args.json:
        print(json.dumps({"role": args.role, "results": [r.to_json() for r in results]}, indent=2))
        return 0
    print(f"{args.role}: share of labelled face/hand frames where the behavior looks at the same")
    print(f"({len(annotations)} handovers; phases and phase ends from the annotations)")
    width = max(len(r.behavior) for r in results)
    print(f"  {'behavior':<{width}}  {'all':>6} {'reach':>6} {'transf':>6} {'retrt':>6}")
    for r in results:
        phases = " ".join(
            f"{100 * r.phase_share(p):6.1f}" for p in ("reach", "transfer", "retreat")
        )
        print(f"  {r.behavior:<{width}}  {100 * r.share:6.1f} {phases}")
    if len(results) > 1:
        print(f"most humanlike for the {args.role}: {results[0].behavior}")
    return 0


def _fit(args: argparse.Namespace) -> int:
    import yaml

    from gazebot.apps.annotations import load_annotations, summarize
    from gazebot.apps.annotations.fit import (
        fit_human_model,
        human_behavior_document,
        retreat_face_delay_s,
    )

    annotations = load_annotations(args.dir)
    model = fit_human_model(annotations, args.role, min_count=args.min_count)
    seconds = summarize(annotations).phase_seconds(args.role)
    doc = human_behavior_document(model, seconds)
    header = (
        f"# Data-driven behavior fitted to the {args.role}s' gaze in {model.n_handovers}\n"
        f"# annotated human-human handovers (seed 6.2). Regenerate with:\n"
        f"#   {model.fitted_by}\n"
    )
    text = header + yaml.safe_dump(doc, sort_keys=False, width=100)
    if args.output:
        args.output.write_text(text, encoding="utf-8")
        print(f"wrote {args.output}")
    else:
        print(text)
    delay = retreat_face_delay_s(annotations, args.role)
    print(
        f"# patterns kept: {len(model.patterns)} covering {100 * model.coverage:.1f}% of "
        f"handovers; hand_face_delay_s (median face delay after the retreat starts): {delay:.3f}"
    )
    return 0
