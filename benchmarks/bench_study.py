"""Bradley-Terry fit time: gazebot's Hunter MM (vectorised on the win matrix) against ``choix``
measured in the same run on the same comparisons."""

from __future__ import annotations

import itertools

import numpy as np

from benchmarks.common import Result, median_time

# Seed Table 6.1, likability (video study; rows Face, Hand, L-FH, S-FH; averaged, fractional).
TABLE_6_1_LIKABILITY = np.array(
    [[0, 6.75, 2.75, 2.25], [17.25, 0, 3.5, 4.75], [21.25, 20.5, 0, 8], [21.75, 19.25, 16, 0]]
)
TOL = 1e-10


def _comparisons(g: int, participants: int, seed: int = 0) -> list[tuple[int, int]]:
    """Every participant compares every ordered pair once; winner drawn from a BT model."""
    rng = np.random.default_rng(seed)
    s = rng.uniform(0.3, 3.0, g)
    data = []
    for _ in range(participants):
        for i, j in itertools.permutations(range(g), 2):
            data.append((i, j) if rng.random() < s[i] / (s[i] + s[j]) else (j, i))
    return data


def run() -> list[Result]:
    import choix

    from gazebot.study.bradley_terry import fit_bradley_terry

    def probs(theta: np.ndarray) -> np.ndarray:
        e = np.exp(theta - theta.max())
        return e / e.sum()

    results = []
    w = TABLE_6_1_LIKABILITY
    diff = np.abs(fit_bradley_terry(w, tol=TOL).p - probs(choix.ilsr_pairwise_dense(w, tol=TOL)))
    ours = median_time(lambda: fit_bradley_terry(w, tol=TOL), repeat=15, number=20)
    peer = median_time(
        lambda: choix.ilsr_pairwise_dense(w, tol=TOL, max_iter=1000), repeat=15, number=20
    )
    results.append(
        Result(
            "BT fit, seed Table 6.1 likability (4 conditions, fractional)",
            ours * 1e3,
            peer * 1e3,
            "ms",
            "choix.ilsr_pairwise_dense",
            note=f"tol {TOL:g}, max |dP| {diff.max():.1e}",
        )
    )

    for g, n in ((3, 24), (10, 24)):
        data = _comparisons(g, n)
        arr = np.asarray(data)

        def ours_fn(arr=arr, g=g):
            wins = np.zeros((g, g))
            np.add.at(wins, (arr[:, 0], arr[:, 1]), 1.0)
            return fit_bradley_terry(wins, tol=TOL)

        ours = median_time(ours_fn, repeat=9, number=5)
        mm = median_time(
            lambda data=data, g=g: choix.mm_pairwise(g, data, tol=TOL, max_iter=100_000),
            repeat=9,
            number=5,
        )
        ilsr = median_time(
            lambda data=data, g=g: choix.ilsr_pairwise(g, data, tol=TOL, max_iter=1000),
            repeat=9,
            number=5,
        )
        p_ours = ours_fn().p
        d_mm = np.abs(p_ours - probs(choix.mm_pairwise(g, data, tol=TOL, max_iter=100_000))).max()
        d_ilsr = np.abs(p_ours - probs(choix.ilsr_pairwise(g, data, tol=TOL))).max()
        label = f"BT fit, {g} conditions x {n} participants ({len(data)} comparisons)"
        results.append(
            Result(
                label,
                ours * 1e3,
                mm * 1e3,
                "ms",
                "choix.mm_pairwise",
                note=f"tol {TOL:g}, max |dP| {d_mm:.1e}",
            )
        )
        results.append(
            Result(
                label,
                ours * 1e3,
                ilsr * 1e3,
                "ms",
                "choix.ilsr_pairwise",
                note=f"tol {TOL:g}, max |dP| {d_ilsr:.1e}",
            )
        )
    return results
