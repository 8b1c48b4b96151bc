"""The in-person studies' reach-start ANOVA and familiarity (seed 6.3.3, 6.4.5), pinned against
sums of squares and moments written out by hand."""

from __future__ import annotations

import argparse
import csv
import json
import math

import pytest

from gazebot.apps.cli import study as study_cli
from gazebot.apps.study.in_person import (
    familiarity_summary,
    reach_start_anova,
    read_in_person,
)


def run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="gazebot")
    study_cli.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(argv)
    return args.func(args)


# Reach-start times (s) of three gaze conditions.
TIMES = {"face": [1.0, 2.0, 3.0], "hand": [2.0, 3.0, 4.0], "face-hand-face": [5.0, 6.0, 7.0]}


def test_anova_matches_the_sums_of_squares_by_hand():
    # Grand mean 33/9; condition means 2, 3, 6.
    # SS_between = 3 (2 - 11/3)^2 + 3 (3 - 11/3)^2 + 3 (6 - 11/3)^2 = (75 + 12 + 147) / 9 = 26
    # SS_within = 3 * ((-1)^2 + 0 + 1^2) = 6
    # F = (26 / 2) / (6 / 6) = 13; for F(2, 6), p = (1 + 2 F / 6)^(-6 / 2) = (6 / 32)^3
    res = reach_start_anova(TIMES)
    assert (res.df_between, res.df_within) == (2, 6)
    assert res.f == pytest.approx(13.0, rel=1e-12)
    assert res.p == pytest.approx((6 / 32) ** 3, rel=1e-9)


def test_familiarity_mean_and_sample_sd_by_hand():
    # M = 8 / 5 = 1.6; SD = sqrt((3 * 0.6^2 + 0.4^2 + 1.4^2) / 4) = sqrt(0.8)
    res = familiarity_summary([1, 1, 2, 1, 3])
    assert (res.mean, res.n) == (pytest.approx(1.6), 5)
    assert res.sd == pytest.approx(math.sqrt(0.8), rel=1e-12)


def test_anova_needs_two_conditions_and_within_freedom():
    with pytest.raises(ValueError, match="at least two gaze conditions"):
        reach_start_anova({"face": [1.0, 2.0]})
    with pytest.raises(ValueError, match="more times than conditions"):
        reach_start_anova({"face": [1.0], "hand": [2.0]})


def _write(path, rows):
    cols = ["participant", "session", "first", "second", "first_reach_start_time",
            "second_reach_start_time", "familiarity", "mode"]
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        w.writerows(rows)
    return path


def _responses(tmp_path):
    return _write(tmp_path / "r.csv", [
        # participant 1 (familiarity 1): face 1, hand 2 / face-hand-face 5, face 2
        [1, 1, "face", "hand", "1", "2", "1", "in-person"],
        [1, 2, "face-hand-face", "face", "5", "2", "1", "in-person"],
        # participant 2 (familiarity 3, asked once): hand 3, face-hand-face 6 / hand 4, face 3
        [2, 1, "hand", "face-hand-face", "3", "6", "3", "in-person"],
        [2, 2, "hand", "face", "4", "3", "", "in-person"],
        [3, 1, "face-hand-face", "hand", "7", "", "2", "in-person"],  # one time not measured
        [9, 1, "face", "hand", "100", "100", "5", "video"],  # another group: not counted
    ])


def test_read_in_person_groups_times_by_the_behavior_shown_and_skips_video_rows(tmp_path):
    data = read_in_person(_responses(tmp_path))
    assert {k: sorted(v) for k, v in data.reach_start.items()} == TIMES
    assert sorted(data.familiarity.values()) == [1, 2, 3]


def test_study_in_person_cli_prints_f_p_and_familiarity(tmp_path, capsys):
    assert run(["study", "in-person", str(_responses(tmp_path)), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["reach_start_anova"]["F"] == pytest.approx(13.0)
    assert doc["reach_start_anova"]["p"] == pytest.approx((6 / 32) ** 3)
    # Familiarity 1, 3, 2: M = 2, SD = sqrt((1 + 1 + 0) / 2) = 1
    assert doc["familiarity"] == {"M": pytest.approx(2.0), "SD": pytest.approx(1.0), "n": 3}
    assert run(["study", "in-person", str(_responses(tmp_path))]) == 0
    out = capsys.readouterr().out
    assert "F(2, 6) = 13.000, p = 0.007" in out and "M = 2.00, SD = 1.00" in out


@pytest.mark.parametrize(
    "row, message",
    [
        ([1, 1, "face", "hand", "soon", "2", "1", "in-person"], "first_reach_start_time"),
        ([1, 1, "face", "hand", "1", "inf", "1", "in-person"], "second_reach_start_time"),
        ([1, 1, "face", "hand", "1", "2", "6", "in-person"], "expected an integer 1-5"),
    ],
)
def test_bad_cells_name_the_file_line_and_column(tmp_path, row, message):
    path = _write(tmp_path / "bad.csv", [row])
    with pytest.raises(ValueError, match=message) as err:
        read_in_person(path)
    assert "bad.csv: line 2" in str(err.value)


def test_two_familiarity_answers_of_one_participant_are_an_error(tmp_path):
    path = _write(tmp_path / "twice.csv", [
        [1, 1, "face", "hand", "1", "2", "1", "in-person"],
        [1, 2, "hand", "face", "1", "2", "4", "in-person"],
    ])
    with pytest.raises(ValueError, match="line 3.*answered 1 on an earlier line, 4 here"):
        read_in_person(path)
