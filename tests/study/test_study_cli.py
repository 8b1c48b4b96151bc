"""``gazebot study plan|render|analyze|fit-wins`` end to end through the command-line module."""

from __future__ import annotations

import argparse
import csv
import json

import pytest
from study_responses import responses_from_tables, write_responses
from study_seed_tables import TABLE_6_1, TABLE_6_2

from gazebot.cli import study as study_cli


def run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="gazebot")
    sub = parser.add_subparsers(dest="command")
    study_cli.register(sub)
    args = parser.parse_args(argv)
    return args.func(args)


def _write_table(path, names, wins):
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["", *names])
        for name, row in zip(names, wins, strict=True):
            w.writerow([name, *row])
    return path


@pytest.mark.parametrize("measure", list(TABLE_6_2))
def test_fit_wins_json_reproduces_table_6_2(tmp_path, capsys, measure):
    names = ["Face", "Hand", "L-FH", "S-FH"]
    path = _write_table(tmp_path / "w.csv", names, TABLE_6_2[measure]["wins"])
    assert run(["study", "fit-wins", str(path), "--participants", "24", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert set(doc) == {"conditions", "p", "chi2", "df", "p_value"}
    assert doc["conditions"] == names and doc["df"] == 3
    assert [round(p, 2) for p in doc["p"]] == TABLE_6_2[measure]["P"]
    assert round(doc["p_value"], 2) == TABLE_6_2[measure]["p_value"]


def test_fit_wins_rejects_totals_that_do_not_match_participants(tmp_path):
    path = _write_table(tmp_path / "w.csv", ["a", "b"], [[0, 10], [10, 0]])
    with pytest.raises(ValueError, match="expected --participants 24"):
        run(["study", "fit-wins", str(path), "--participants", "24"])


def test_plan_command_writes_balanced_plan(tmp_path, capsys):
    out = tmp_path / "plan.csv"
    argv = [
        "study",
        "plan",
        "--behaviors",
        "hand-face,face-hand-face,hand",
        "--condition",
        "posture",
        "--participants",
        "24",
        "--seed",
        "9",
        "--out",
        str(out),
        "--json",
    ]
    assert run(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["position_balanced"] and doc["carryover_balanced"]
    assert doc["sessions_per_participant"] == 12
    with out.open() as fh:
        assert len(list(csv.DictReader(fh))) == 288


def test_plan_command_rejects_incomplete_block(tmp_path):
    with pytest.raises(ValueError, match="multiple of 12"):
        run(
            [
                "study",
                "plan",
                "--condition",
                "fragility",
                "--participants",
                "10",
                "--out",
                str(tmp_path / "p.csv"),
            ]
        )


def test_analyze_command_json_and_plot(tmp_path, capsys):
    rows = responses_from_tables({"small-box": TABLE_6_1, "large-box": TABLE_6_2})
    path = write_responses(rows, tmp_path / "responses.csv")
    plot = tmp_path / "fig.png"
    argv = [
        "study",
        "analyze",
        str(path),
        "--json",
        "--plot",
        str(plot),
        "--behaviors",
        "face,hand,long-face-hand,short-face-hand",
    ]
    assert run(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    lik = doc["per_level"]["large-box"]["likability"]
    assert [round(p, 2) for p in lik["p"]] == TABLE_6_2["likability"]["P"]
    assert round(lik["p_value"], 2) == 0.01
    assert (tmp_path / "fig-small-box.png").is_file() and (tmp_path / "fig-large-box.png").is_file()
    assert run(["study", "analyze", str(path)]) == 0
    assert "chi2=" in capsys.readouterr().out


def test_render_command_with_synthetic_renderer(tmp_path, capsys):
    plan = tmp_path / "plan.csv"
    run(["study", "plan", "--condition", "object-size", "--participants", "12", "--out", str(plan)])
    argv = [
        "study",
        "render",
        str(plan),
        "--out",
        str(tmp_path / "out"),
        "--renderer",
        "synthetic",
        "--width",
        "32",
        "--height",
        "24",
        "--fps",
        "5",
        "--card-seconds",
        "0.2",
        "--workers",
        "1",
        "--no-progress",
    ]
    assert run(argv) == 0
    out = capsys.readouterr().out
    assert "6 handover videos (6 rendered, 0 cached), 12 pair videos, 144 session files" in out


def test_render_command_rejects_unknown_scene_before_rendering(tmp_path):
    plan = tmp_path / "plan.csv"
    run(
        [
            "study",
            "plan",
            "--condition",
            "object-size",
            "--participants",
            "12",
            "--scene",
            "small-box=no-such-scene",
            "--out",
            str(plan),
        ]
    )
    with pytest.raises(ValueError, match="unknown scene 'no-such-scene'"):
        run(["study", "render", str(plan), "--out", str(tmp_path / "out"), "--no-progress"])
    assert not (tmp_path / "out").exists()
