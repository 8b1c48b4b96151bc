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
