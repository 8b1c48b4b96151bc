"""Hunter's MM Bradley-Terry fit and the seed's chi-square reproduce Tables 6.1/6.2 and choix."""

from __future__ import annotations

import itertools

import choix
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from study_seed_tables import CONDITIONS, N_PARTICIPANTS, TABLE_6_1, TABLE_6_2

from gazebot.apps.study.bradley_terry import fit_bradley_terry, log_likelihood
from gazebot.apps.study.stats import bradley_terry_chi2, likelihood_ratio_chi2

CASES = [("6.1", m, d) for m, d in TABLE_6_1.items()] + [
    ("6.2", m, d) for m, d in TABLE_6_2.items()
]


@pytest.mark.parametrize(("table", "measure", "data"), CASES, ids=lambda v: str(v)[:20])
def test_mm_fit_reproduces_seed_table_win_probabilities(table, measure, data):
    fit = fit_bradley_terry(np.array(data["wins"]), CONDITIONS)
    assert fit.converged
    np.testing.assert_allclose(fit.wins, data["a"])
    assert np.round(fit.p, 2).tolist() == pytest.approx(data["P"], abs=1e-9)
    assert fit.p.sum() == pytest.approx(1.0)


@pytest.mark.parametrize("measure", list(TABLE_6_2))
def test_seed_chi2_reproduces_table_6_2_p_values(measure):
    data = TABLE_6_2[measure]
    fit = fit_bradley_terry(np.array(data["wins"]), CONDITIONS)
    chi = bradley_terry_chi2(fit.wins, fit.p, N_PARTICIPANTS)
    assert chi.df == 3
    assert round(chi.p_value, 2) == data["p_value"]


@pytest.mark.parametrize("measure", list(TABLE_6_1))
def test_seed_chi2_for_video_study_is_significant_below_1e4(measure):
    fit = fit_bradley_terry(np.array(TABLE_6_1[measure]["wins"]), CONDITIONS)
    chi = bradley_terry_chi2(fit.wins, fit.p, N_PARTICIPANTS)
    assert chi.p_value < 1e-4  # the seed: "all of the chi-square values are large (p < 0.0001)"


@pytest.mark.parametrize(("table", "measure", "data"), CASES, ids=lambda v: str(v)[:20])
def test_seed_chi2_equals_likelihood_ratio_statistic(table, measure, data):
    w = np.array(data["wins"])
    fit = fit_bradley_terry(w, CONDITIONS)
    seed = bradley_terry_chi2(fit.wins, fit.p, N_PARTICIPANTS)
    lr = likelihood_ratio_chi2(w, fit.p)
    assert seed.chi2 == pytest.approx(lr.chi2, rel=1e-10)
    ll0 = log_likelihood(w, np.full(4, 0.25))
    assert seed.chi2 == pytest.approx(2 * (fit.log_likelihood - ll0), rel=1e-10)


@pytest.mark.parametrize(("table", "measure", "data"), CASES, ids=lambda v: str(v)[:20])
def test_mm_fit_agrees_with_choix_on_fractional_tables(table, measure, data):
    w = np.array(data["wins"], dtype=float)
    theta = choix.ilsr_pairwise_dense(w, tol=1e-12, max_iter=1000)
    p_choix = np.exp(theta) / np.exp(theta).sum()
    np.testing.assert_allclose(fit_bradley_terry(w).p, p_choix, atol=1e-7)


def test_mm_fit_agrees_with_choix_mm_on_integer_comparisons():
    rng = np.random.default_rng(3)
    g = 6
    strength = rng.uniform(0.5, 3.0, g)
    data = []
    for i, j in itertools.permutations(range(g), 2):
        for _ in range(10):
            data.append(
                (i, j) if rng.random() < strength[i] / (strength[i] + strength[j]) else (j, i)
            )
    w = np.zeros((g, g))
    for winner, loser in data:
        w[winner, loser] += 1
    theta = choix.mm_pairwise(g, data, tol=1e-12, max_iter=100_000)
    p_choix = np.exp(theta) / np.exp(theta).sum()
    np.testing.assert_allclose(fit_bradley_terry(w).p, p_choix, atol=1e-6)


def test_equal_wins_give_equal_probabilities_and_zero_chi2():
    w = np.full((3, 3), 12.0)
    fit = fit_bradley_terry(w)
    np.testing.assert_allclose(fit.p, 1 / 3)
    chi = bradley_terry_chi2(fit.wins, fit.p, 24)
    assert chi.chi2 == pytest.approx(0.0, abs=1e-9)
    assert chi.p_value == pytest.approx(1.0)


def test_condition_that_never_wins_is_rejected_with_clear_error():
    w = np.array([[0, 5, 3], [0, 0, 0], [2, 4, 0]], dtype=float)
    with pytest.raises(ValueError, match="never wins"):
        fit_bradley_terry(w)


@pytest.mark.parametrize(
    "bad",
    [np.zeros((2, 3)), np.array([[0, -1], [1, 0]]), np.array([[0, np.nan], [1, 0]]), [[0]]],
)
def test_malformed_win_matrix_raises_value_error(bad):
    with pytest.raises(ValueError):
        fit_bradley_terry(np.asarray(bad, dtype=float))


@settings(max_examples=40, deadline=None)
@given(
    arrays(np.float64, (5, 5), elements=st.floats(0.25, 30.0)),
)
def test_mm_fit_solves_score_equations_and_matches_choix_for_random_tables(w):
    np.fill_diagonal(w, 0.0)
    fit = fit_bradley_terry(w)
    p = fit.p
    n = w + w.T
    # Maximum likelihood: each condition's observed wins equal its expected wins.
    expected = (n * p[:, None] / (p[:, None] + p[None, :])).sum(axis=1)
    np.testing.assert_allclose(expected, w.sum(axis=1), rtol=1e-7, atol=1e-7)
    theta = choix.ilsr_pairwise_dense(w, tol=1e-12, max_iter=1000)
    np.testing.assert_allclose(p, np.exp(theta) / np.exp(theta).sum(), atol=1e-6)
