"""``gazebot behaviors list`` and ``show``."""

from __future__ import annotations

import argparse
import importlib
import json

import pytest

from gazebot.core.behaviors import seed_behaviors
from gazebot.core.behaviors.spec import AtEvent, AtNever

cli = importlib.import_module("gazebot.apps.cli.behaviors")


def run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="gazebot")
    sub = parser.add_subparsers(dest="command", required=True)
    cli.register(sub)
    args = parser.parse_args(argv)
    return args.func(args)


#: The seed's gaze behaviors (chapter 6): the built-ins whose YAML says ``source: seed``.
SEED_BEHAVIORS = seed_behaviors()


def test_list_json_lists_builtins_with_their_variants(capsys):
    assert run(["behaviors", "list", "--json", "--dir", "/nonexistent"]) == 0
    doc = json.loads(capsys.readouterr().out)
    by_name = {b["name"]: b for b in doc["behaviors"]}
    assert by_name["face-hand-face-as-studied"]["extends"] == "face-hand-face"
    assert by_name["face"]["builtin"] is True


def test_list_text_has_one_line_per_behavior(capsys):
    assert run(["behaviors", "list"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert any(line.startswith("human-receiver ") for line in lines)


def test_show_prints_the_resolved_variant(capsys):
    assert run(["behaviors", "show", "hand-face-as-studied"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["parameters"]["retreat_face"]["after"] == "robot_retreat_started"


def test_show_unknown_behavior_raises_for_the_dispatcher():
    with pytest.raises(FileNotFoundError):
        run(["behaviors", "show", "nope"])


def test_show_diagram_writes_the_machine_with_its_phase_and_gaze_states(tmp_path, capsys):
    out = tmp_path / "fhf.md"
    assert run(["behaviors", "show", "face-hand-face", "--diagram", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert text.startswith("```mermaid\n") and "stateDiagram-v2" in text
    # The handover state's phases (the one phase the behavior reads) and the gaze states.
    for phase in ("idle", "reach", "transfer", "retreat", "done"):
        assert f'state "{phase}" as behavior_handover_{phase}' in text
    for gaze in ("face", "hand"):
        assert f'state "{gaze}" as behavior_gaze_{gaze}' in text
    # The gaze shifts are the machine's transitions, labelled with the segment's timing and the
    # rule that picks the phase's expected end.
    assert (
        "timer [reach: 0.5 of the reach (end: latest of tracking, event, robot plan; else 1.01 s)]"
        in text
    )
    assert "timer [retreat: 0.5 of the retreat (end: first known of" in text
    # New handovers, the end of a handover and the carried gaze are rules of the machine too.
    assert "phase [new handover]" in text and "phase [handover done]" in text
    assert "[same handover: the gaze carries]" in text
    # ...and so are the handover state's merging rules (first reach wins, grasp, stale events).
    assert (
        "behavior_handover_idle --> behavior_handover_reach: reach_started [not older than the "
        "last phase change] | robot_reach_started" in text
    )
    assert "robot_grasped [not older than the last phase change: the grasp is transfer" in text
    assert "tracking_restored [after the loss]" in text


def test_show_diagram_into_a_missing_folder_is_a_usage_error_naming_the_option(tmp_path):
    from gazebot.apps.cli.errors import UsageError

    out = tmp_path / "no-such-folder" / "fhf.md"
    with pytest.raises(UsageError, match=r"^--diagram .*fhf\.md: output folder does not exist$"):
        run(["behaviors", "show", "face-hand-face", "--diagram", str(out)])
    assert not out.parent.exists()


def test_the_diagram_is_the_machine_the_behavior_runs_on():
    from gazebot.core.behaviors import BehaviorMachine, load_behavior
    from gazebot.core.behaviors.machine import diagram

    spec = load_behavior("hand-face-as-studied")
    m = BehaviorMachine(spec)
    text = diagram(spec)
    for state in m.states:
        phase, gaze = state.split("_")[:2]
        assert f"as behavior_handover_{phase}" in text and f"as behavior_gaze_{gaze}" in text
    assert "timer [retreat: robot_retreat_started]" in text


@pytest.mark.parametrize("name", SEED_BEHAVIORS)
def test_a_seed_behaviors_diagram_shows_every_segment_that_decides_its_targets(name):
    from gazebot.core.behaviors import load_behavior
    from gazebot.core.behaviors.machine import diagram

    spec = load_behavior(name)
    text = diagram(spec)
    for seg in spec.segments:
        at = spec.resolve(seg)
        if isinstance(at, AtNever):
            continue
        assert f"behavior_gaze_{seg.target.replace('_', '-')}" in text
        label = f"timer [{seg.phase}: "
        if isinstance(at, AtEvent):
            label += at.after.value
        elif at.fraction == 0:
            label += f"at the {seg.phase}'s start"
        else:
            label += f"{at.fraction:g} of the {seg.phase} (end: "
        assert label in text, label
    assert f"timer [held {spec.tracking_lost.hold_s:g} s]" in text


def test_the_documented_diagram_is_the_one_the_machine_draws():
    from gazebot.core.behaviors import load_behavior
    from gazebot.core.behaviors.machine import diagram
    from tests.documentation import documentation_text

    assert diagram(load_behavior("face-hand-face")).strip() in documentation_text()


@pytest.mark.parametrize("name", SEED_BEHAVIORS)
def test_a_seed_behaviors_diagram_has_no_empty_alternative_in_an_edge_label(name):
    from gazebot.core.behaviors import load_behavior
    from gazebot.core.behaviors.machine import diagram

    for line in diagram(load_behavior(name)).splitlines():
        if "-->" in line and ": " in line:
            label = line.partition(": ")[2]
            assert all(part.strip() for part in label.split(" | ")), line
