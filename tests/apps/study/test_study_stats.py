"""The seed's proportion tests (eqs 6.3-6.6), equivalence tests and the Wilcoxon bias test."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats as sps

from gazebot.apps.study.stats import (
    matched_equivalence,
    matched_proportion_difference,
    position_bias_test,
    unmatched_equivalence,
    unmatched_proportion_difference,
)


def _binary(n_both: int, n_only_a: int, n_only_b: int, n_neither: int):
    a = [1] * n_both + [1] * n_only_a + [0] * n_only_b + [0] * n_neither
    b = [1] * n_both + [0] * n_only_a + [1] * n_only_b + [0] * n_neither
    return np.array(a, float), np.array(b, float)


def test_matched_difference_matches_equations_6_3_and_6_4():
    xa, xb = _binary(10, 7, 3, 4)  # n = 24
    n = 24
    p_b, p_c = 7 / n, 3 / n
    se = math.sqrt((p_b + p_c - (p_b - p_c) ** 2) / n)
    res = matched_proportion_difference(xa, xb)
    assert res.difference == pytest.approx(p_b - p_c)
    assert res.se == pytest.approx(se)
    assert res.z == pytest.approx((p_b - p_c) / se)
    assert res.p_value == pytest.approx(2 * sps.norm.sf((p_b - p_c) / se))


def test_identical_answers_show_no_difference_and_equivalence():
    xa, xb = _binary(12, 0, 0, 12)
    assert matched_proportion_difference(xa, xb).p_value == 1.0
    assert matched_equivalence(xa, xb).p_value == 0.0


def test_matched_equivalence_is_two_one_sided_tests_at_margin():
    xa, xb = _binary(30, 5, 4, 61)  # n = 100, difference 0.01
    res = matched_equivalence(xa, xb, margin=0.1)
    se = matched_proportion_difference(xa, xb).se
    expected = max(sps.norm.sf((0.01 + 0.1) / se), sps.norm.cdf((0.01 - 0.1) / se))
    assert res.p_value == pytest.approx(expected)
    assert res.p_value < 0.05  # small, nearly equal discordance in 100 participants
    assert matched_equivalence(*_binary(10, 7, 3, 4), margin=0.1).p_value > 0.15  # seed-sized n


def test_matched_tests_reject_mismatched_or_out_of_range_input():
    with pytest.raises(ValueError, match="same participants"):
        matched_proportion_difference(np.ones(3), np.ones(4))
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        matched_proportion_difference(np.array([2.0]), np.array([1.0]))
    with pytest.raises(ValueError, match="margin"):
        matched_equivalence(*_binary(3, 1, 1, 3), margin=0)


def test_unmatched_difference_uses_pooled_proportion_of_equation_6_6():
    res = unmatched_proportion_difference(18, 24, 12, 24)
    p_d = 30 / 48
    se = math.sqrt(p_d * (1 - p_d) * (1 / 24 + 1 / 24))
    assert res.difference == pytest.approx(0.25)
    assert res.se == pytest.approx(se)
    assert res.p_value == pytest.approx(2 * sps.norm.sf(0.25 / se))


def test_unmatched_equivalence_and_count_validation():
    res = unmatched_equivalence(500, 1000, 510, 1000, margin=0.1)
    se = math.sqrt(0.5 * 0.5 / 1000 + 0.51 * 0.49 / 1000)
    assert res.p_value == pytest.approx(
        max(sps.norm.sf((-0.01 + 0.1) / se), sps.norm.cdf((-0.01 - 0.1) / se))
    )
    assert res.p_value < 1e-4
    assert unmatched_equivalence(12, 24, 13, 24).p_value > 0.15
    with pytest.raises(ValueError, match="outside"):
        unmatched_proportion_difference(25, 24, 1, 24)


def test_bias_test_matches_scipy_and_reports_centred_s():
    d = np.array([0.5, -0.25, 0.0, 0.25, -0.5, -0.75, 0.25, 0.125, -0.125, 0.5])
    res = position_bias_test(d)
    nz = d[d != 0]
    ref = sps.wilcoxon(nz)
    assert res.p_value == pytest.approx(ref.pvalue)
    ranks = sps.rankdata(np.abs(nz))
    assert res.statistic == pytest.approx(ranks[nz > 0].sum())
    assert res.s == pytest.approx(res.statistic - len(nz) * (len(nz) + 1) / 4)
    assert res.n == 9


def test_bias_test_without_any_preference_gives_s_zero_p_one():
    res = position_bias_test(np.zeros(24))
    assert (res.s, res.p_value) == (0.0, 1.0)


def test_strong_first_position_bias_is_detected():
    assert position_bias_test(np.linspace(0.2, 0.9, 24)).p_value < 0.001


def test_centred_s_matches_seed_reporting_for_per_session_answers():
    # The seed's video-study likability S = -156.5 fits 312 per-session answers, 155 "1st" and
    # 157 "2nd": all ranks tie at (m + 1) / 2, so S = (m + 1) / 4 * (n_1st - n_2nd).
    res = position_bias_test(np.array([1.0] * 155 + [-1.0] * 157))
    assert res.s == pytest.approx(-156.5)
    assert res.p_value > 0.85


def test_bias_z_is_the_tie_corrected_normal_score_scipy_reports():
    from scipy import stats as sps

    d = np.array([0.5, -0.2, 0.5, 1, -1, 0.3, 0.5, -0.5, 0.2, 0.1, 0.0])
    res = sps.wilcoxon(d, method="approx", zero_method="wilcox", correction=False)
    b = position_bias_test(d)
    assert abs(b.z) == pytest.approx(abs(res.zstatistic), rel=1e-12)
    assert b.z > 0 and b.s > 0  # more "1st" than "2nd": positive S and z


def test_bias_p_quoted_with_z_is_its_normal_p_as_the_seed_quotes_it():
    # 6.4.4: "like: z = -0.68, p = 0.50 ... humanlike: z = 1.36, p = 0.17". With few differences
    # and no ties scipy's p is exact and belongs to no z: one "1st" gives z = 1, exact p = 1.
    one = position_bias_test(np.array([0.5]))
    assert one.z == pytest.approx(1.0) and one.p_value == pytest.approx(1.0)
    assert one.p_z == pytest.approx(0.3173, abs=1e-4)
    d = np.array([0.5, -0.2, 0.5, 1, -1, 0.3, 0.5, -0.5, 0.2, 0.1, 0.0])
    b = position_bias_test(d)
    assert b.p_z == pytest.approx(2 * sps.norm.sf(abs(b.z)))
    assert round(2 * sps.norm.sf(0.68), 2) == 0.50 and round(2 * sps.norm.sf(1.36), 2) == 0.17


def test_one_sided_p_is_half_the_two_sided_p_in_the_observed_direction():
    rng = np.random.default_rng(3)
    a = (rng.random(24) < 0.7).astype(float)
    b = (rng.random(24) < 0.4).astype(float)
    two = matched_proportion_difference(a, b, sides="two")
    one = matched_proportion_difference(a, b, sides="one")
    assert one.z == two.z and one.p_value == pytest.approx(two.p_value / 2)
    flipped = matched_proportion_difference(b, a, sides="one")
    assert flipped.p_value == pytest.approx(one.p_value) and flipped.z == -one.z
    u_two = unmatched_proportion_difference(15, 24, 9, 24, sides="two")
    u_one = unmatched_proportion_difference(15, 24, 9, 24, sides="one")
    assert u_one.p_value == pytest.approx(u_two.p_value / 2)
    with pytest.raises(ValueError, match="sides"):
        matched_proportion_difference(a, b, sides="both")
