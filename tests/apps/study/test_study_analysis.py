"""From a responses CSV to the seed's averaged win matrices, P_i, chi-square and level tests."""

from __future__ import annotations

import numpy as np
import pytest
from study_responses import BEHAVIORS, responses_from_tables, write_responses
from study_seed_tables import TABLE_6_1, TABLE_6_2

from gazebot.apps.study.analysis import analyze, read_responses, read_win_matrix, win_matrix
from gazebot.apps.study.plots import plot_preferences
from gazebot.apps.study.stats import bradley_terry_chi2


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


def _with_first_share(rows: list[dict], share_first: float | None, seed: int) -> list[dict]:
    """The rows with every answer redrawn: 1 (first handover) with probability ``share_first``,
    whatever the behaviors, i.e. a known position bias. ``None``: no bias by construction, the
    participants 13-24 give the mirror answers (1 <-> 2) of participants 1-12 to random ones."""
    rng = np.random.default_rng(seed)
    qs = ("q1", "q2", "q3", "q4", "q5")
    drawn = {}
    out = []
    for r in rows:
        r = dict(r)
        k = (r["participant"], r["level"], r["first"], r["second"])
        mirror = (r["participant"] - 12, r["level"], r["first"], r["second"])
        for q in qs:
            if share_first is None and mirror in drawn:
                r[q] = 3 - drawn[mirror][q]
            else:
                r[q] = 1 if rng.random() < (share_first or 0.5) else 2
        drawn[k] = r
        out.append(r)
    return out


def _participant_differences(rows: list[dict], questions: tuple[str, ...]) -> np.ndarray:
    """Independent of gazebot: per participant share of 1s minus share of 2s."""
    answers: dict[int, list[int]] = {}
    for r in rows:
        answers.setdefault(int(r["participant"]), []).extend(int(r[q]) for q in questions)
    return np.array([np.mean(np.equal(a, 1)) - np.mean(np.equal(a, 2)) for a in answers.values()])


@pytest.mark.parametrize(
    ("share_first", "biased"), [(0.75, True), (None, False)], ids=["strong-bias", "no-bias"]
)
def test_bias_test_equals_scipy_wilcoxon_and_detects_a_first_position_bias(
    tmp_path, share_first, biased
):
    from scipy import stats as sps

    base = responses_from_tables({"small-box": TABLE_6_1, "large-box": TABLE_6_2})
    rows = _with_first_share(base, share_first, seed=7)
    result = analyze(read_responses(write_responses(rows, tmp_path / "r.csv")), behaviors=BEHAVIORS)
    for measure, questions in (
        ("likability", ("q1", "q2")),
        ("anthropomorphism", ("q3", "q4")),
        ("timing-communication", ("q5",)),
    ):
        d = _participant_differences(rows, questions)
        d = d[d != 0]
        ref = sps.wilcoxon(d, zero_method="wilcox", alternative="two-sided")
        w_plus = sps.wilcoxon(d, zero_method="wilcox", alternative="greater").statistic
        b = result.bias[measure]
        assert b.n == d.size
        assert b.p_value == pytest.approx(ref.pvalue, rel=1e-12)
        assert b.statistic == pytest.approx(w_plus)
        assert b.s == pytest.approx(w_plus - d.size * (d.size + 1) / 4)
        if biased:
            assert b.p_value < 1e-4 and b.s > 0  # 24 participants, 3 in 4 answers "1st"
        else:
            assert b.s == 0 and b.p_value == pytest.approx(1.0)  # exactly symmetric differences


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
    from gazebot.apps.study.analysis import position_differences

    responses = read_responses(two_level_csv)
    per_participant = position_differences(responses, ("q5",))
    per_session = position_differences(responses, ("q5",), unit="session")
    assert per_participant.shape == (24,)
    assert per_session.shape == (24 * 12 * 2,)
    assert set(np.unique(per_session)) <= {-1.0, 1.0}
    with pytest.raises(ValueError, match="bias unit"):
        position_differences(responses, ("q5",), unit="question")


def _rows(level: str, table: dict, offset: int = 0, group: str | None = None, condition=None):
    rows = responses_from_tables({level: table})
    for r in rows:
        r["participant"] += offset
        if condition:
            r["condition"] = condition
        if group is not None:
            r["group"] = group
    return rows


def _pick(comparisons, measure="likability", pair=("face", "hand")):
    return [c for c in comparisons if c.measure == measure and (c.behavior_i, c.behavior_j) == pair]


def test_one_level_in_two_groups_uses_the_unmatched_tests_of_equations_6_5_and_6_6(tmp_path):
    from gazebot.apps.study.stats import unmatched_equivalence, unmatched_proportion_difference

    # Like the seed's video vs in-person comparison (H5): both groups number participants 1..24.
    rows = _rows("small-box", TABLE_6_1, group="in-person")
    rows += _rows("small-box", TABLE_6_2, group="video")
    result = analyze(read_responses(write_responses(rows, tmp_path / "r.csv")), behaviors=BEHAVIORS)
    assert result.levels == ["in-person:small-box", "video:small-box"]
    assert result.per_level["video:small-box"]["likability"].participants == 24
    assert len(result.comparisons) == 3 * 6
    assert {c.design for c in result.comparisons} == {"unmatched"}
    (c,) = _pick(result.comparisons)
    assert (c.group_a, c.group_b, c.n_a, c.n_b) == ("in-person", "video", 24, 24)
    # X = the win-matrix cell (Tables B.1-B.6), n = 24 per group.
    ref = unmatched_proportion_difference(6.75, 24, 15.0, 24)
    assert c.difference.z == pytest.approx(ref.z) and c.difference.p_value < 0.05
    assert c.equivalence.p_value == pytest.approx(unmatched_equivalence(6.75, 24, 15.0, 24).p_value)
    doc = result.to_json()["level_comparisons"][0]
    assert doc["design"] == "unmatched" and doc["groups"] == ["in-person", "video"]


def test_two_levels_seen_by_disjoint_participants_are_compared_unmatched(tmp_path):
    rows = _rows("small-box", TABLE_6_1) + _rows("large-box", TABLE_6_2, offset=24)
    result = analyze(read_responses(write_responses(rows, tmp_path / "r.csv")), behaviors=BEHAVIORS)
    (c,) = _pick(result.comparisons)
    assert c.design == "unmatched" and (c.n_a, c.n_b) == (24, 24)
    assert (c.level_a, c.level_b) == ("small-box", "large-box")
    assert c.proportion_a == pytest.approx(6.75 / 24) and c.proportion_b == pytest.approx(15 / 24)


def test_same_participants_in_two_levels_stay_matched(two_level_csv):
    result = analyze(read_responses(two_level_csv), behaviors=BEHAVIORS)
    assert {c.design for c in result.comparisons} == {"matched"}
    assert {(c.n_a, c.n_b) for c in result.comparisons} == {(24, 24)}


def test_levels_of_different_conditions_are_not_compared(tmp_path):
    rows = _rows("small-box", TABLE_6_1, condition="object-size")
    rows += _rows("large-box", TABLE_6_2, condition="object-size")
    rows += _rows("sitting", TABLE_6_2, offset=24, condition="posture")
    rows += _rows("standing", TABLE_6_1, offset=24, condition="posture")
    result = analyze(read_responses(write_responses(rows, tmp_path / "r.csv")), behaviors=BEHAVIORS)
    pairs = {(c.level_a, c.level_b, c.design) for c in result.comparisons}
    assert pairs == {("small-box", "large-box", "matched"), ("sitting", "standing", "matched")}


def test_bias_is_tested_per_question_as_in_6_4_and_sides_can_be_overridden(two_level_csv):
    responses = read_responses(two_level_csv)
    seed = analyze(responses, behaviors=BEHAVIORS)
    one = analyze(responses, behaviors=BEHAVIORS, sides="one")
    two = analyze(responses, behaviors=BEHAVIORS, sides="two")
    assert list(seed.bias_per_question) == ["q1", "q2", "q3", "q4", "q5"]
    assert seed.to_json()["bias_per_question"]["q5"]["z"] == seed.bias_per_question["q5"].z
    assert seed.to_json()["bias_per_question"]["q5"]["p_z"] == seed.bias_per_question["q5"].p_z
    assert (seed.sides, one.sides, two.sides) == ("seed", "one", "two")
    # two levels answered by the same participants: matched, one-sided as the seed's B.7
    assert {(c.sides, c.table) for c in seed.comparisons} == {("one", "B.7")}
    assert {c.sides for c in two.comparisons} == {"two"}
    for c1, c2 in zip(one.comparisons, two.comparisons, strict=True):
        assert c1.difference.z == c2.difference.z
        assert c1.difference.p_value == pytest.approx(c2.difference.p_value / 2)


_CONDITIONS = {
    "object-size": ("small-box", "large-box"),
    "fragility": ("plastic-bottle", "glass-bottle"),
    "posture": ("sitting", "standing"),
}


@pytest.fixture(scope="module")
def video_and_in_person(tmp_path_factory):
    """The seed's section 6.4 design: per condition, 24 video and 24 in-person participants
    (numbered from 1 in each group) each answer both levels; the groups answer differently."""
    rows = []
    for k, (condition, (a, b)) in enumerate(_CONDITIONS.items()):
        for group, (ta, tb) in (
            ("video", (TABLE_6_1, TABLE_6_2)),
            ("in-person", (TABLE_6_2, TABLE_6_1)),
        ):
            for level, table in ((a, ta), (b, tb)):
                rows += _rows(level, table, offset=24 * k, group=group, condition=condition)
    path = write_responses(rows, tmp_path_factory.mktemp("resp") / "responses.csv")
    return read_responses(path)


@pytest.mark.parametrize(
    ("table", "design", "condition", "sides"),
    [
        ("B.7", "matched", "object-size", "one"),
        ("B.8", "matched", "fragility", "one"),
        ("B.9", "matched", "posture", "one"),
        ("B.10", "unmatched", "object-size", "two"),
        ("B.11", "unmatched", "fragility", "two"),
        ("B.12", "unmatched", "posture", "two"),
    ],
)
def test_each_b_table_test_has_the_seeds_sidedness(
    video_and_in_person, table, design, condition, sides
):
    """Matched level tests (B.7-B.9) one-sided, unmatched video vs in-person (B.10-B.12)
    two-sided; the p-value is recomputed here from z with that sidedness."""
    from scipy.stats import norm

    result = analyze(video_and_in_person, behaviors=BEHAVIORS)
    levels = set(_CONDITIONS[condition])
    tests = [c for c in result.comparisons if c.table == table]
    # matched: one test per group; unmatched: one per level; each x 3 measures x 6 pairs
    assert len(tests) == 2 * 3 * 6
    for c in tests:
        assert c.design == design and c.sides == sides and {c.level_a, c.level_b} <= levels
        tail = norm.sf(abs(c.difference.z))
        assert c.difference.p_value == pytest.approx(tail if sides == "one" else 2 * tail)
    doc = [d for d in result.to_json()["level_comparisons"] if d["table"] == table]
    assert {d["sides"] for d in doc} == {sides}
    # --sides overrides the seed's for every test
    for override in ("one", "two"):
        forced = analyze(video_and_in_person, behaviors=BEHAVIORS, sides=override)
        assert {c.sides for c in forced.comparisons if c.table == table} == {override}


def test_unmatched_levels_of_one_group_have_no_seed_table_but_the_seed_sidedness(tmp_path):
    rows = _rows("small-box", TABLE_6_1) + _rows("large-box", TABLE_6_2, offset=24)
    result = analyze(read_responses(write_responses(rows, tmp_path / "r.csv")), behaviors=BEHAVIORS)
    assert {(c.design, c.table, c.sides) for c in result.comparisons} == {("unmatched", "", "two")}


def test_a_sample_without_a_finite_fit_is_named_in_the_error(tmp_path):
    """An in-person group with two sessions entered so far: the error says which sample."""
    path = tmp_path / "r.csv"
    head = "participant,session,condition,level,first,second,q1,q2,q3,q4,q5,group\n"
    rows = [
        f"{p},{k},,,{a},{b},1,2,1,2,1,video"
        for p in (1, 2)
        for k, (a, b) in enumerate([("face", "hand"), ("hand", "face")], start=1)
    ] + ["3,1,,,face,hand,1,1,1,1,1,in-person", "3,2,,,hand,face,2,2,2,2,2,in-person"]
    path.write_text(head + "\n".join(rows) + "\n")
    with pytest.raises(ValueError, match=r"sample 'in-person:' \(1 participants, 2 sessions\)"):
        analyze(read_responses(path))


def test_bias_is_also_tested_per_group_as_the_seed_tests_each_study(tmp_path):
    """Video participants who always pick the 2nd, in-person ones who pick either: the video
    group's bias shows on its own, the in-person group's does not."""
    path = tmp_path / "r.csv"
    head = "participant,session,condition,level,first,second,q1,q2,q3,q4,q5,group\n"
    pairs = [("face", "hand"), ("hand", "face")]
    rows = []
    for p in range(1, 15):  # over 13: scipy's quick normal p, not a permutation test
        for k, (a, b) in enumerate(pairs, start=1):
            rows.append(f"{p},{k},,,{a},{b},2,2,2,2,2,video")
            even = "1" if (p + k) % 2 else "2"
            rows.append(f"{p},{k},,,{a},{b},{','.join([even] * 5)},in-person")
    path.write_text(head + "\n".join(rows) + "\n")
    result = analyze(read_responses(path))
    assert set(result.bias_by_group) == {"video", "in-person"}
    video, live = result.bias_by_group["video"], result.bias_by_group["in-person"]
    assert video["q1"].z < -2.5 and video["q1"].p_z < 0.01 and video["likability"].p_value < 0.01
    assert live["q1"].z == 0 and live["q1"].p_z == 1.0
    assert result.to_json()["bias_by_group"]["video"]["q5"]["p_z"] == video["q5"].p_z


def test_the_6_3_behaviors_are_reported_in_the_order_of_tables_6_1_and_6_2(tmp_path):
    from gazebot.apps.study.analysis import behaviors_of

    path = tmp_path / "r.csv"
    head = "participant,session,condition,level,first,second,q1,q2,q3,q4,q5\n"
    pairs = [("short-face-hand", "hand"), ("face", "long-face-hand"), ("hand", "face")]
    rows = [f"1,{k},,,{a},{b},1,2,1,2,1" for k, (a, b) in enumerate(pairs, start=1)]
    path.write_text(head + "\n".join(rows) + "\n")
    assert behaviors_of(read_responses(path)) == [
        "face",
        "hand",
        "long-face-hand",
        "short-face-hand",
    ]
