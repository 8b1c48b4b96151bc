"""``gazebot behaviors list`` and ``show``."""

from __future__ import annotations

import argparse
import importlib
import json

import pytest

cli = importlib.import_module("gazebot.cli.behaviors")


def run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="gazebot")
    sub = parser.add_subparsers(dest="command", required=True)
    cli.register(sub)
    args = parser.parse_args(argv)
    return args.func(args)


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
    for phase in ("idle", "reach", "transfer", "retreat", "done"):
        assert f'state "{phase}" as behavior_handover_{phase}' in text
    for gaze in ("reach_face", "reach_hand", "transfer_hand", "retreat_face"):
        assert f"as behavior_handover_{gaze}" in text
    # The gaze shifts are the machine's transitions, labelled with the segment's timing.
    assert (
        "behavior_handover_reach --> behavior_handover_reach_hand: timer [0.5 of the reach]" in text
    )
    assert (
        "behavior_handover_reach_hand --> behavior_handover_transfer_hand: transfer_started" in text
    )


def test_show_diagram_into_a_missing_folder_is_a_usage_error_naming_the_option(tmp_path):
    from gazebot.cli.errors import UsageError

    out = tmp_path / "no-such-folder" / "fhf.md"
    with pytest.raises(UsageError, match=r"^--diagram .*fhf\.md: output folder does not exist$"):
        run(["behaviors", "show", "face-hand-face", "--diagram", str(out)])
    assert not out.parent.exists()


def test_the_diagram_is_the_machine_the_behavior_runs_on():
    from gazebot.behaviors import BehaviorMachine, load_behavior
    from gazebot.behaviors.machine import diagram

    spec = load_behavior("hand-face-as-studied")
    m = BehaviorMachine(spec)
    text = diagram(spec)
    for state in m.states:
        phase, gaze = state.split("_")[:2]
        assert f"as behavior_handover_{phase}_{gaze}" in text
    assert "timer [robot_retreat_started]" in text
