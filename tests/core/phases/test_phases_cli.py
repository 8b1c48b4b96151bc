"""``gazebot phases FILE [--online] [--json] [--config FILE] [--method M]``."""

from __future__ import annotations

import argparse
import json

import numpy as np
import pytest

from gazebot.apps.cli import phases as cli
from gazebot.core.phases.synthetic import SyntheticOptions, generate


def _run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="gazebot")
    cli.register(parser.add_subparsers())
    args = parser.parse_args(["phases", *argv])
    return args.func(args)


@pytest.fixture(scope="module")
def csv_file(tmp_path_factory):
    case = generate(3, SyntheticOptions(handovers=2, rate=60, robot_evidence=True))
    path = case.trajectory.to_csv(tmp_path_factory.mktemp("cli") / "handover.csv")
    return path, case


def test_json_lists_phase_start_end(csv_file, capsys):
    path, case = csv_file
    assert _run([str(path), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["units"] == {"time": "s", "length": "m", "file_length": "m"}
    assert doc["rate_hz"] == pytest.approx(60.0, rel=0.01) and doc["method"] == "gazebot"
    out = doc["segments"]
    assert [o["phase"] for o in out] == ["reach", "transfer", "retreat"] * 2
    assert all({"phase", "start", "end"} <= o.keys() and "detected_at" not in o for o in out)
    assert abs(out[1]["start"] - case.truth[0].transfer_start) <= 0.1


def test_online_json_adds_detected_at(csv_file, capsys):
    path, _ = csv_file
    assert _run([str(path), "--online", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)["segments"]
    assert [o["phase"] for o in out] == ["reach", "transfer", "retreat"] * 2
    assert all(o["detected_at"] >= o["start"] for o in out)


def test_text_output_is_a_table(csv_file, capsys):
    path, _ = csv_file
    assert _run([str(path)]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0].startswith("# ") and "60.0 Hz" in lines[0] and "(shown in m, s)" in lines[0]
    assert lines[1].split() == ["handover", "phase", "start", "end", "duration"]
    assert len(lines) == 8


def test_config_option_is_used(csv_file, tmp_path, capsys):
    path, _ = csv_file
    cfg = tmp_path / "p.yaml"
    cfg.write_text("reach_onset_speed: 5.0\nmin_approach: 5.0\n")
    assert _run([str(path), "--config", str(cfg), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["segments"] == []


def test_malformed_csv_error_names_line_and_column(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text(
        "t,giver_hand_x,giver_hand_y,giver_hand_z,receiver_hand_x,receiver_hand_y,receiver_hand_z\n"
        "0,1,0,0,0.5,0,0\n0.1,1,0,0,0.5,oops,0\n"
    )
    with pytest.raises(ValueError, match=r"bad.csv: line 3, column 'receiver_hand_y'"):
        _run([str(bad)])


def test_dispatcher_reports_errors_with_exit_code_2(tmp_path, capsys):
    from gazebot.apps.cli import main

    assert main(["phases", str(tmp_path / "missing.csv")]) == 2
    assert "gazebot: error:" in capsys.readouterr().err


@pytest.fixture(scope="module")
def cut_csv(tmp_path_factory):
    """The reviewer's recording cut mid-transfer: at 2.98 s, the true release is at 3.26 s."""
    case = generate(3, SyntheticOptions(rate=100))
    tr = case.trajectory
    cut = tr.take(np.flatnonzero(tr.t <= 2.98))
    path = cut.to_csv(tmp_path_factory.mktemp("cli_cut") / "cut.csv")
    return path, float(cut.t[-1]), case


def test_json_of_a_recording_cut_mid_transfer_ends_in_the_transfer(cut_csv, capsys):
    path, t_last, case = cut_csv
    assert _run([str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)["segments"]
    assert [o["phase"] for o in out] == ["reach", "transfer"]
    assert out[1]["end"] == pytest.approx(t_last)
    assert abs(out[1]["start"] - case.truth[0].transfer_start) <= 0.1


def test_online_json_of_a_recording_cut_mid_transfer_ends_in_the_transfer(cut_csv, capsys):
    path, t_last, case = cut_csv
    assert _run([str(path), "--online", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)["segments"]
    assert [o["phase"] for o in out] == ["reach", "transfer"]
    assert out[1]["end"] == pytest.approx(t_last)
    assert all(o["start"] <= o["detected_at"] <= t_last for o in out)


@pytest.mark.parametrize("online", [False, True])
def test_table_marks_a_phase_the_recording_stops_in(tmp_path, capsys, online):
    case = generate(3)
    cut = case.trajectory.take(slice(0, int(len(case.trajectory) * 0.45)))
    path = cut.to_csv(tmp_path / "cut.csv")
    assert _run([str(path)] + (["--online"] if online else [])) == 0
    rows = capsys.readouterr().out.strip().splitlines()[2:]
    assert rows[-1].split()[1] == "transfer" and rows[-1].endswith("(to end of data)")
    assert not any(r.endswith("(to end of data)") for r in rows[:-1])
