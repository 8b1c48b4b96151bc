"""Significance tests of the seed's preference analysis (chapter 6).

- :func:`bradley_terry_chi2`: equations 6.1-6.2 (Yamaoka et al.): with decimal logs
  ``B = n sum_{i<j} log10(P_i + P_j) - sum_i a_i log10 P_i`` and
  ``chi2 = n g (g - 1) ln 2 - 2 B ln 10`` on ``g - 1`` degrees of freedom. This is exactly the
  likelihood-ratio statistic ``2 (ln L(P) - ln L(equal P))`` of the Bradley-Terry model against
  "all conditions equal" when every pair was compared ``n`` times (the ``ln 10`` converts the
  decimal logs; ``n g (g-1)/2`` comparisons at probability 1/2 give the ``ln 2`` term).
  :func:`likelihood_ratio_chi2` is the same statistic for any number of comparisons per pair.
- :func:`position_bias_test`: one-sample Wilcoxon signed-rank test of first/second bias.
- :func:`matched_proportion_difference` / :func:`matched_equivalence`: equations 6.3-6.4 and the
  McNemar-type equivalence test (two one-sided tests) for the same participants in two levels.
- :func:`unmatched_proportion_difference` / :func:`unmatched_equivalence`: equations 6.5-6.6 for
  two groups of participants.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats as sps

from gazebot.apps.study.bradley_terry import check_win_matrix


@dataclass(frozen=True)
class ChiSquare:
    """A chi-square statistic with its degrees of freedom and upper-tail p-value."""

    chi2: float
    df: int
    p_value: float


def bradley_terry_chi2(wins_per_condition: np.ndarray, p: np.ndarray, n: float) -> ChiSquare:
    """The seed's equations 6.1-6.2.

    ``wins_per_condition``: a_i (row sums of the averaged win matrix); ``p``: fitted P_i;
    ``n``: number of participants (each compared every pair once after averaging).
    """
    a = np.asarray(wins_per_condition, dtype=float)
    p = np.asarray(p, dtype=float)
    g = a.size
    if p.shape != a.shape or g < 2:
        raise ValueError("a_i and P_i must be vectors of the same length >= 2")
    if not (math.isfinite(n) and n > 0):
        raise ValueError(f"number of participants must be a finite positive number, got {n}")
    if np.any(p <= 0):
        raise ValueError("all P_i must be positive for the chi-square of eq. 6.2")
    iu, ju = np.triu_indices(g, k=1)
    b = n * np.sum(np.log10(p[iu] + p[ju])) - np.sum(a * np.log10(p))
    chi2 = n * g * (g - 1) * math.log(2) - 2 * b * math.log(10)
    chi2 = max(float(chi2), 0.0)  # rounding can give -1e-15 for equal P_i
    return ChiSquare(chi2=chi2, df=g - 1, p_value=float(sps.chi2.sf(chi2, g - 1)))


def likelihood_ratio_chi2(wins: np.ndarray, p: np.ndarray) -> ChiSquare:
    """Likelihood-ratio chi-square of the Bradley-Terry fit ``p`` against equal P_i, for any
    number of comparisons per pair; equal to :func:`bradley_terry_chi2` when every pair was
    compared ``n`` times."""
    w = check_win_matrix(wins)
    p = np.asarray(p, dtype=float)
    g = w.shape[0]
    ratio = p[:, None] / (p[:, None] + p[None, :])
    mask = w > 0
    ll = float(np.sum(w[mask] * np.log(ratio[mask])))
    ll0 = -float(np.sum(np.triu(w + w.T, k=1))) * math.log(2)
    chi2 = max(2.0 * (ll - ll0), 0.0)
    return ChiSquare(chi2=chi2, df=g - 1, p_value=float(sps.chi2.sf(chi2, g - 1)))


@dataclass(frozen=True)
class BiasTest:
    """One-sample Wilcoxon signed-rank test of ``differences`` against 0.

    ``statistic``: scipy's W (sum of ranks of the positive differences); ``s``: the centred
    statistic ``W - m (m + 1) / 4`` (m = nonzero differences) that SAS reports as S and the seed
    quotes in 6.3; ``z``: S over its standard deviation under H0 (with the tie correction), the
    normal-approximation score the seed quotes per question in 6.4; ``n``: number of nonzero
    differences; ``p_value``: two-sided, scipy's (exact for few differences without ties);
    ``p_z``: two-sided p of ``z`` under the normal approximation, the p the seed quotes with its
    z (6.4.4: "like: z = -0.68, p = 0.50").
    """

    statistic: float
    s: float
    n: int
    p_value: float
    z: float = 0.0
    p_z: float = 1.0

    def as_json(self, with_p_z: bool = True) -> dict[str, float]:
        """The test as the analysis' JSON reports it (the seed's names: W, S, z)."""
        out = {"W": self.statistic, "S": self.s, "z": self.z, "n": self.n, "p_value": self.p_value}
        if with_p_z:
            out["p_z"] = self.p_z
        return out


def position_bias_test(differences: np.ndarray) -> BiasTest:
    """One-sample Wilcoxon signed-rank test that ``differences`` are centred on 0.

    For the first/second bias pass per participant (share of "1st" answers - share of "2nd"
    answers); zeros are dropped (Wilcoxon's convention); all zeros give S = 0, p = 1.
    """
    d = np.asarray(differences, dtype=float).ravel()
    if d.size == 0 or not np.all(np.isfinite(d)):
        raise ValueError("bias test needs at least one finite difference")
    nz = d[d != 0]
    m = nz.size
    if m == 0:
        return BiasTest(statistic=0.0, s=0.0, n=0, p_value=1.0, z=0.0)
    ranks = sps.rankdata(np.abs(nz))
    w_plus = float(ranks[nz > 0].sum())
    res = sps.wilcoxon(nz, zero_method="wilcox", alternative="two-sided")
    s = w_plus - m * (m + 1) / 4.0
    _, tie_counts = np.unique(np.abs(nz), return_counts=True)
    var = m * (m + 1) * (2 * m + 1) / 24.0 - float(np.sum(tie_counts**3 - tie_counts)) / 48.0
    z = s / math.sqrt(var) if var > 0 else 0.0
    p_z = float(2 * sps.norm.sf(abs(z)))
    return BiasTest(statistic=w_plus, s=s, n=int(m), p_value=float(res.pvalue), z=float(z), p_z=p_z)


@dataclass(frozen=True)
class ProportionTest:
    """A z-test of a proportion difference: ``difference`` (p_b - p_c), its standard error,
    ``z`` and the p-value (two-sided for a difference test; for an equivalence test the larger
    of the two one-sided p-values, small = equivalent within +-margin)."""

    difference: float
    se: float
    z: float
    p_value: float
    margin: float | None = None


SIDES = ("one", "two")


@dataclass(frozen=True)
class SeedTable:
    """One of the seed's Appendix B tables of binary proportion difference tests: the design of
    its test (``matched``: the same participants in two levels, eqs 6.3-6.4; ``unmatched``: the
    video against the in-person participants, eqs 6.5-6.6), the condition it compares and the
    sidedness of its p-values."""

    name: str
    design: str
    condition: str
    sides: str


# The sidedness of the seed's difference tests, one fact per design: the matched tests of H2-H4
# (Tables B.7-B.9) one-sided in the observed direction, the unmatched video-against-in-person
# tests of H5 (Tables B.10-B.12) two-sided, as issue 22 reads the dissertation's Appendix B (the
# tables are not in the seed excerpt; its H5, "Observers of a handover and participants in a
# handover have different preference ratings", names no direction).
SEED_SIDES: dict[str, str] = {"matched": "one", "unmatched": "two"}

SEED_TABLES: tuple[SeedTable, ...] = tuple(
    SeedTable(name, design, condition, SEED_SIDES[design])
    for name, design, condition in (
        ("B.7", "matched", "object-size"),
        ("B.8", "matched", "fragility"),
        ("B.9", "matched", "posture"),
        ("B.10", "unmatched", "object-size"),
        ("B.11", "unmatched", "fragility"),
        ("B.12", "unmatched", "posture"),
    )
)


def seed_sides(design: str) -> str:
    """The sidedness the seed's tables use for a ``matched`` or ``unmatched`` difference test."""
    if design not in SEED_SIDES:
        raise ValueError(f"design must be one of {sorted(SEED_SIDES)}, got {design!r}")
    return SEED_SIDES[design]


def seed_table(design: str, condition: str) -> SeedTable | None:
    """The Appendix B table that reports a ``design`` test between the levels of ``condition``
    (None: the seed has no such table, e.g. a between-subject condition of our own)."""
    return next((t for t in SEED_TABLES if (t.design, t.condition) == (design, condition)), None)


def _z_test(diff: float, se: float, sides: str = "two") -> ProportionTest:
    """z = diff / se; ``sides="two"``: p = 2 P(Z > |z|); ``"one"``: p = P(Z > |z|), one-sided in
    the direction observed (the seed's matched Tables B.7-B.9 report the preferred condition in
    bold with such a p; :data:`SEED_SIDES` holds which design is which)."""
    if sides not in SIDES:
        raise ValueError(f"sides must be 'one' or 'two', got {sides!r}")
    if se <= 0:
        # No variability: identical answers in both samples (diff 0) cannot show a difference.
        z = 0.0 if diff == 0 else math.copysign(math.inf, diff)
        return ProportionTest(diff, 0.0, z, (1.0 if sides == "two" else 0.5) if diff == 0 else 0.0)
    z = diff / se
    tail = float(sps.norm.sf(abs(z)))
    return ProportionTest(diff, se, z, 2 * tail if sides == "two" else tail)


def _tost(diff: float, se: float, margin: float) -> ProportionTest:
    if not (math.isfinite(margin) and margin > 0):
        raise ValueError(f"equivalence margin must be a finite positive number, got {margin}")
    if se <= 0:
        inside = abs(diff) < margin
        return ProportionTest(diff, 0.0, 0.0, 0.0 if inside else 1.0, margin)
    p_low = float(sps.norm.sf((diff + margin) / se))  # H0: diff <= -margin
    p_high = float(sps.norm.cdf((diff - margin) / se))  # H0: diff >= +margin
    z = (diff + margin) / se if p_low >= p_high else (diff - margin) / se
    return ProportionTest(diff, se, z, max(p_low, p_high), margin)


def _paired(x_a: np.ndarray, x_b: np.ndarray) -> tuple[float, float]:
    a = np.asarray(x_a, dtype=float).ravel()
    b = np.asarray(x_b, dtype=float).ravel()
    if a.shape != b.shape or a.size == 0:
        raise ValueError("matched tests need the same participants (same length) in both levels")
    if np.any((a < 0) | (a > 1)) or np.any((b < 0) | (b > 1)) or not np.all(np.isfinite(a + b)):
        raise ValueError("preferences must be proportions in [0, 1]")
    d = a - b
    n = d.size
    diff = float(d.mean())
    # For 0/1 answers mean(d^2) = p_b + p_c (the discordant shares), so this is eq. 6.3 exactly.
    var = float(np.mean(d**2) - diff**2) / n
    return diff, math.sqrt(max(var, 0.0))


def matched_proportion_difference(
    x_a: np.ndarray, x_b: np.ndarray, sides: str = "two"
) -> ProportionTest:
    """Equations 6.3-6.4: do the same participants prefer condition i over j equally often in
    levels a and b? ``x_a[k]``, ``x_b[k]``: participant k's preference for i over j (1 = i, 0 =
    j; fractions allowed when answers were averaged). With 0/1 answers ``p_b``/``p_c`` are the
    shares preferring i only in a / only in b and ``var = (p_b + p_c - (p_b - p_c)^2) / n``.
    ``sides``: ``"two"`` or ``"one"`` (see :func:`_z_test`)."""
    return _z_test(*_paired(x_a, x_b), sides)


def matched_equivalence(x_a: np.ndarray, x_b: np.ndarray, margin: float = 0.1) -> ProportionTest:
    """McNemar-type equivalence test for matched proportions: two one-sided z-tests that the
    difference lies within ``+-margin`` (the seed uses 0.1), with the Wald variance of eq. 6.3."""
    return _tost(*_paired(x_a, x_b), margin)


def _check_count(x: float, n: int, name: str) -> None:
    if not n > 0:
        raise ValueError(f"{name}: group size must be positive, got {n}")
    if not (math.isfinite(x) and 0 <= x <= n):
        raise ValueError(f"{name}: count {x} outside [0, {n}]")


def unmatched_proportion_difference(
    x_b: float, n_b: int, x_c: float, n_c: int, sides: str = "two"
) -> ProportionTest:
    """Equations 6.5-6.6: two groups, ``x_b`` of ``n_b`` and ``x_c`` of ``n_c`` participants
    prefer condition i over j. Pooled ``p_d = (x_b + x_c) / (n_b + n_c)`` and
    ``var = p_d (1 - p_d) (1/n_b + 1/n_c)`` (the seed prints ``1/n_b - 1/n_c``, a typo: it would
    be 0 for its equal groups of 24)."""
    _check_count(x_b, n_b, "group b")
    _check_count(x_c, n_c, "group c")
    p_b, p_c = x_b / n_b, x_c / n_c
    p_d = (x_b + x_c) / (n_b + n_c)
    se = math.sqrt(p_d * (1 - p_d) * (1 / n_b + 1 / n_c))
    return _z_test(p_b - p_c, se, sides)


def unmatched_equivalence(
    x_b: float, n_b: int, x_c: float, n_c: int, margin: float = 0.1
) -> ProportionTest:
    """Equivalence of two independent proportions within ``+-margin``: two one-sided z-tests
    with the unpooled variance ``p_b (1 - p_b) / n_b + p_c (1 - p_c) / n_c``."""
    _check_count(x_b, n_b, "group b")
    _check_count(x_c, n_c, "group c")
    p_b, p_c = x_b / n_b, x_c / n_c
    se = math.sqrt(p_b * (1 - p_b) / n_b + p_c * (1 - p_c) / n_c)
    return _tost(p_b - p_c, se, margin)
