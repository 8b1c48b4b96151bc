"""``gazebot study plan|render|analyze|fit-wins`` end to end through the command-line module."""

from __future__ import annotations

import argparse
import csv
import json

import pytest
from study_responses import responses_from_tables, write_responses
from study_seed_tables import TABLE_6_1, TABLE_6_2

from gazebot.apps.cli import study as study_cli


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
    assert set(doc) == {"conditions", "p", "chi2", "df", "p_value", "pair_totals_differ"}
    assert doc["pair_totals_differ"] == []
    assert doc["conditions"] == names and doc["df"] == 3
    assert [round(p, 2) for p in doc["p"]] == TABLE_6_2[measure]["P"]
    assert round(doc["p_value"], 2) == TABLE_6_2[measure]["p_value"]


def test_fit_wins_with_a_pair_answered_23_of_24_warns_and_uses_its_own_total(tmp_path, capsys):
    """Like the seed's Table B.3, where one pair was answered by 23 of 24 participants."""
    import numpy as np

    from gazebot.apps.study.bradley_terry import fit_bradley_terry
    from gazebot.apps.study.stats import likelihood_ratio_chi2

    names = ["Face", "Hand", "L-FH", "S-FH"]
    wins = np.array(TABLE_6_2["likability"]["wins"], dtype=float)
    wins[0, 1] -= 1  # Face vs Hand: 14 + 9 = 23 answers
    path = _write_table(tmp_path / "w.csv", names, wins.tolist())
    assert run(["study", "fit-wins", str(path), "--participants", "24", "--json"]) == 0
    captured = capsys.readouterr()
    assert "(Face, Hand) + (Hand, Face) = 23, not --participants 24" in captured.err
    doc = json.loads(captured.out)
    assert doc["pair_totals_differ"] == [["Face", "Hand", 23.0]]
    fit = fit_bradley_terry(wins, names)
    np.testing.assert_allclose(doc["p"], fit.p)
    assert doc["chi2"] == pytest.approx(likelihood_ratio_chi2(wins, fit.p).chi2)
    # One win fewer for Face lowers its P_i below the complete table's, and only a little.
    full = fit_bradley_terry(np.array(TABLE_6_2["likability"]["wins"]), names)
    assert full.p[0] - 0.02 < doc["p"][0] < full.p[0]


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


def test_plan_of_the_seed_6_3_design_needs_no_condition_and_no_out(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    argv = "study plan --behaviors face,hand,short-face-hand,long-face-hand --participants 24"
    assert run([*argv.split(), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["sessions_per_participant"] == 12 and doc["condition"] == ""
    assert doc["gaze_mode"] == "head-only"
    assert doc["robot"] == "jaco2"  # 6.3.2: the Jaco-2 with "a simple robot head"
    with (tmp_path / "plan.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 24 * 12
    for p in range(1, 25):
        pairs = [(r["first"], r["second"]) for r in rows if r["participant"] == str(p)]
        assert len(pairs) == len(set(pairs)) == 12  # each ordered pair once


def test_plan_with_a_condition_defaults_to_the_as_studied_behaviors(tmp_path, capsys):
    argv = ["study", "plan", "--condition", "posture", "--participants", "12"]
    assert run([*argv, "--out", str(tmp_path / "p.csv"), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["behaviors"] == ["hand-face-as-studied", "face-hand-face-as-studied", "hand"]
    assert doc["gaze_mode"] == "eyes-only"
    assert doc["robot"] == "sawyer"  # 6.4.3: "implemented on a Sawyer cobot"


def test_plan_robot_defaults_to_the_designs_robot_and_robot_overrides_it(tmp_path, capsys):
    from gazebot.apps.study.plan import read_plan

    out = tmp_path / "p.csv"
    assert run(["study", "plan", "--participants", "12", "--out", str(out)]) == 0
    assert {s.robot for s in read_plan(out)} == {"jaco2"}
    assert "robot jaco2" in capsys.readouterr().out
    argv = ["study", "plan", "--participants", "12", "--robot", "sawyer", "--out", str(out)]
    assert run(argv) == 0
    assert {s.robot for s in read_plan(out)} == {"sawyer"}


def test_serve_and_export_on_a_folder_that_is_not_a_rendered_study_say_so(tmp_path):
    with pytest.raises(ValueError, match="is not a rendered study"):
        run(["study", "export", str(tmp_path), "--out", str(tmp_path / "r.csv")])
    with pytest.raises(ValueError, match="is not a rendered study"):
        run(["study", "serve", str(tmp_path), "--port", "0"])


@pytest.mark.parametrize(
    "name", ["http://study.example", "study.example:8000", "a/b", "", "no space"]
)
def test_serve_allowed_host_must_be_a_host_name(tmp_path, name):
    with pytest.raises(ValueError, match="--allowed-host: .* is not a host name"):
        run(["study", "serve", str(tmp_path), "--port", "0", "--allowed-host", name])
