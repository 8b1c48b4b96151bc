"""Bad input to ``gazebot study``: clear ``ValueError`` s instead of tracebacks, NaN or silence."""

from __future__ import annotations

import argparse
import json
import math

import pytest
from study_responses import responses_from_tables, write_responses
from study_seed_tables import TABLE_6_1, TABLE_6_2

from gazebot.apps.cli import study as study_cli
from gazebot.apps.study.analysis import read_responses, read_win_matrix
from gazebot.apps.study.conditions import CONDITION_LEVELS
from gazebot.apps.study.plan import make_plan, read_plan, write_plan
from gazebot.apps.study.stats import bradley_terry_chi2, matched_equivalence


def run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="gazebot")
    sub = parser.add_subparsers(dest="command")
    study_cli.register(sub)
    args = parser.parse_args(argv)
    return args.func(args)


def _plan_argv(out, behaviors="hand-face,face-hand-face,hand", condition="posture"):
    return ["study", "plan", "--behaviors", behaviors, "--condition", condition,
            "--participants", "12", "--out", str(out)]  # fmt: skip


@pytest.fixture
def responses_csv(tmp_path):
    rows = responses_from_tables({"small-box": TABLE_6_1, "large-box": TABLE_6_2})
    return write_responses(rows, tmp_path / "responses.csv")


def test_plan_out_directory_is_a_clear_value_error_not_a_traceback(tmp_path):
    with pytest.raises(ValueError, match=r"is a directory; give a file path such as .*plan\.csv"):
        run(_plan_argv(tmp_path))
    with pytest.raises(ValueError, match="is a directory"):
        write_plan(make_plan(participants=12), tmp_path)
    (tmp_path / "file").write_text("x")
    with pytest.raises(ValueError, match="is a file, not a directory"):
        run(_plan_argv(tmp_path / "file" / "plan.csv"))


def test_plan_rejects_unknown_behavior_naming_it_and_listing_available(tmp_path):
    out = tmp_path / "plan.csv"
    with pytest.raises(ValueError, match=r"unknown behavior 'nosuch'; available: .*hand-face"):
        run(_plan_argv(out, behaviors="hand,nosuch,face"))
    assert not out.exists()


def test_plan_rejects_unknown_robot_naming_the_known_ones(tmp_path):
    out = tmp_path / "p.csv"
    with pytest.raises(ValueError, match=r"--robot: unknown robot 'nosuch' \(known: .*jaco2"):
        run(["study", "plan", "--participants", "12", "--robot", "nosuch", "--out", str(out)])
    assert not out.exists()


def test_plan_conditions_come_from_the_plan_module(tmp_path, capsys):
    for condition in CONDITION_LEVELS:
        assert run(_plan_argv(tmp_path / f"{condition}.csv", condition=condition)) == 0
        assert {s.level for s in read_plan(tmp_path / f"{condition}.csv")} == set(
            CONDITION_LEVELS[condition]
        )
    with pytest.raises(SystemExit):
        run(_plan_argv(tmp_path / "x.csv", condition="lighting"))
    assert "invalid choice" in capsys.readouterr().err


@pytest.mark.parametrize("value", ["nan", "inf", "-1", "0"])
def test_fit_wins_participants_must_be_finite_and_positive(tmp_path, capsys, value):
    path = tmp_path / "w.csv"
    path.write_text(",a,b\na,,3\nb,2,\n")
    with pytest.raises(ValueError, match=r"--participants must be a finite number > 0, got"):
        run(["study", "fit-wins", str(path), "--participants", value, "--json"])
    assert capsys.readouterr().out == ""
    with pytest.raises(ValueError, match="finite positive"):
        bradley_terry_chi2([3.0, 2.0], [0.6, 0.4], float(value))


def test_win_matrix_nan_or_inf_cell_is_rejected_with_line_and_column(tmp_path):
    path = tmp_path / "w.csv"
    path.write_text(",a,b\na,,nan\nb,2,\n")
    with pytest.raises(ValueError, match=r"line 2, column 'b': expected a number, got 'nan'"):
        read_win_matrix(path)


@pytest.mark.parametrize("value", ["nan", "inf", "0", "1", "-0.1"])
def test_analyze_margin_must_be_a_finite_proportion(responses_csv, capsys, value):
    with pytest.raises(ValueError, match=r"--margin must be a finite number in \(0, 1\)"):
        run(["study", "analyze", str(responses_csv), "--margin", value, "--json"])
    assert capsys.readouterr().out == ""
    with pytest.raises(ValueError, match="margin"):
        matched_equivalence(
            [1.0, 0.0], [1.0, 1.0], margin=float(value) if value != "1" else math.nan
        )


def test_analyze_plot_must_be_a_png_file(responses_csv, tmp_path):
    with pytest.raises(ValueError, match="is a directory"):
        run(["study", "analyze", str(responses_csv), "--plot", str(tmp_path)])
    with pytest.raises(ValueError, match=r"must end in \.png"):
        run(["study", "analyze", str(responses_csv), "--plot", str(tmp_path / "fig")])


def test_non_utf8_csv_error_names_the_file(tmp_path, responses_csv):
    latin = tmp_path / "latin1.csv"
    latin.write_bytes(responses_csv.read_bytes().replace(b"object-size", b"obj\xe9ct-size", 1))
    with pytest.raises(ValueError, match=r"latin1\.csv: not UTF-8 text \(byte 0xe9"):
        run(["study", "analyze", str(latin)])
    wins = tmp_path / "wins.csv"
    wins.write_bytes(b",Gr\xfcn,b\nGr\xfcn,,3\nb,2,\n")
    with pytest.raises(ValueError, match=r"wins\.csv: not UTF-8 text"):
        run(["study", "fit-wins", str(wins), "--participants", "5"])
    plan = tmp_path / "plan.csv"
    write_plan(make_plan(participants=12), plan)
    plan.write_bytes(plan.read_bytes().replace(b"sawyer", b"s\xe4wyer"))
    with pytest.raises(ValueError, match=r"plan\.csv: not UTF-8 text"):
        read_plan(plan)


def test_utf8_with_byte_order_mark_reads_like_plain_utf8(tmp_path, responses_csv):
    bom = tmp_path / "bom.csv"
    bom.write_bytes(b"\xef\xbb\xbf" + responses_csv.read_bytes())
    assert read_responses(bom) == read_responses(responses_csv)


def test_analyze_json_stays_finite_and_valid(responses_csv, capsys):
    assert run(["study", "analyze", str(responses_csv), "--json"]) == 0
    text = capsys.readouterr().out
    assert "NaN" not in text and "Infinity" not in text
    json.loads(text)


def test_phases_command_non_utf8_trajectory_error_names_the_file(tmp_path):
    # gazebot/apps/cli/phases.py (owned here) turns the loader's UnicodeDecodeError into a clear
    # error;
    # this belongs with tests/phases once its owner takes it over.
    from gazebot.apps.cli import main

    path = tmp_path / "traj.csv"
    path.write_bytes(
        b"t,giver_hand_x,giver_hand_y,giver_hand_z,receiver_hand_x,receiver_hand_y,"
        b"receiver_hand_z\n0,1,0,1,0.5,0,1\n0.1,1,0,1,0.5,0,1 # caf\xe9\n"
    )
    parser = argparse.ArgumentParser(prog="gazebot")
    sub = parser.add_subparsers(dest="command")
    from gazebot.apps.cli import phases as phases_cli

    phases_cli.register(sub)
    args = parser.parse_args(["phases", str(path)])
    with pytest.raises(ValueError, match=r"traj\.csv: not UTF-8 text \(byte 0xe9"):
        args.func(args)
    assert main(["phases", str(path)]) == 2
