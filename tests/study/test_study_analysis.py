"""From a responses CSV to the seed's averaged win matrices, P_i, chi-square and level tests."""

from __future__ import annotations

import numpy as np
import pytest
from study_responses import BEHAVIORS, responses_from_tables, write_responses
from study_seed_tables import TABLE_6_1, TABLE_6_2

from gazebot.study.analysis import analyze, read_responses, read_win_matrix, win_matrix
from gazebot.study.plots import plot_preferences
from gazebot.study.stats import bradley_terry_chi2


@pytest.fixture(scope="module")
def two_level_csv(tmp_path_factory):
    rows = responses_from_tables({"small-box": TABLE_6_1, "large-box": TABLE_6_2})
    return write_responses(rows, tmp_path_factory.mktemp("resp") / "responses.csv")


def test_win_matrix_averages_both_ordered_comparisons(two_level_csv):
    responses = [r for r in read_responses(two_level_csv) if r.level == "small-box"]
    for measure, qs in (("likability", ("q1", "q2")), ("timing-communication", ("q5",))):
        w = win_matrix(responses, BEHAVIORS, qs)
        np.testing.assert_allclose(w, TABLE_6_1[measure]["wins"])
        np.testing.assert_allclose((w + w.T)[~np.eye(4, dtype=bool)], 24)


def test_analysis_of_responses_reproduces_table_6_1_and_6_2(two_level_csv):
    result = analyze(read_responses(two_level_csv), behaviors=BEHAVIORS)
    assert result.behaviors == BEHAVIORS
    assert result.levels == ["small-box", "large-box"]
    for level, table in (("small-box", TABLE_6_1), ("large-box", TABLE_6_2)):
        for measure, data in table.items():
            r = result.per_level[level][measure]
            assert r.participants == 24
            assert np.round(r.fit.p, 2).tolist() == pytest.approx(data["P"], abs=1e-9)
            seed = bradley_terry_chi2(r.fit.wins, r.fit.p, 24)
            assert r.chi2.chi2 == pytest.approx(seed.chi2)
            if "p_value" in data:
                assert round(r.chi2.p_value, 2) == data["p_value"]


def test_level_comparisons_use_matched_participant_preferences(two_level_csv):
    result = analyze(read_responses(two_level_csv), behaviors=BEHAVIORS)
    assert len(result.comparisons) == 3 * 6
    c = next(
        c
        for c in result.comparisons
        if c.measure == "likability" and (c.behavior_i, c.behavior_j) == ("face", "hand")
    )
    assert c.proportion_a == pytest.approx(6.75 / 24)
    assert c.proportion_b == pytest.approx(15 / 24)
    assert c.difference.difference == pytest.approx(6.75 / 24 - 15 / 24)
    assert c.difference.p_value < 0.05  # face vs hand flips between the two tables
    assert 0 <= c.equivalence.p_value <= 1


def test_bias_test_runs_per_measure_with_one_value_per_participant(two_level_csv):
    result = analyze(read_responses(two_level_csv), behaviors=BEHAVIORS)
    assert set(result.bias) == {"likability", "anthropomorphism", "timing-communication"}
    for b in result.bias.values():
        assert b.n <= 24 and 0 <= b.p_value <= 1


def test_json_report_is_serialisable(two_level_csv):
    import json

    doc = json.loads(
        json.dumps(analyze(read_responses(two_level_csv), behaviors=BEHAVIORS).to_json())
    )
    assert doc["per_level"]["large-box"]["likability"]["df"] == 3


def test_bad_answer_is_reported_with_line_and_column(tmp_path):
    rows = responses_from_tables({"x": TABLE_6_1})
    rows[4]["q3"] = 3
    with pytest.raises(ValueError, match="line 6: column 'q3' expected 1"):
        read_responses(write_responses(rows, tmp_path / "r.csv"))
    rows = responses_from_tables({"x": TABLE_6_1})
    for r in rows:
        del r["q5"]
    with pytest.raises(ValueError, match="missing column"):
        read_responses(write_responses(rows, tmp_path / "r2.csv"))


def test_read_win_matrix_checks_names_and_numbers(tmp_path):
    p = tmp_path / "w.csv"
    p.write_text(",a,b\na,,3.5\nb,20.5,\n")
    names, w = read_win_matrix(p)
    assert names == ["a", "b"] and w.tolist() == [[0, 3.5], [20.5, 0]]
    p.write_text(",a,b\na,,x\nb,2,\n")
    with pytest.raises(ValueError, match="expected a number"):
        read_win_matrix(p)
    p.write_text(",a,b\na,1,3\nb,2,\n")
    with pytest.raises(ValueError, match="diagonal"):
        read_win_matrix(p)
    p.write_text(",a,b\nb,,1\na,2,\n")
    with pytest.raises(ValueError, match="differ"):
        read_win_matrix(p)


def test_plot_like_figure_6_3_is_written(two_level_csv, tmp_path):
    result = analyze(read_responses(two_level_csv), behaviors=BEHAVIORS)
    out = plot_preferences(result.per_level["small-box"], tmp_path / "fig.png", title="video")
    assert out.stat().st_size > 5000
    import matplotlib.image as mpimg

    img = mpimg.imread(out)
    assert img.shape[0] > 100 and img.shape[1] > 200


def test_bias_differences_per_participant_or_per_session(two_level_csv):
    from gazebot.study.analysis import position_differences

    responses = read_responses(two_level_csv)
    per_participant = position_differences(responses, ("q5",))
    per_session = position_differences(responses, ("q5",), unit="session")
    assert per_participant.shape == (24,)
    assert per_session.shape == (24 * 12 * 2,)
    assert set(np.unique(per_session)) <= {-1.0, 1.0}
    with pytest.raises(ValueError, match="bias unit"):
        position_differences(responses, ("q5",), unit="question")
