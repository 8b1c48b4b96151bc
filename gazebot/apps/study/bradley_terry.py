"""Bradley-Terry win probabilities by Hunter's (2004) iterative MM algorithm.

The model: condition ``i`` is preferred over ``j`` with probability ``P_i / (P_i + P_j)``. From a
win matrix ``W`` (``W[i, j]`` = how often ``i`` was preferred over ``j``; fractions allowed, as in
the seed's Tables 6.1/6.2 where both ordered comparisons are averaged) the maximum-likelihood ``P``
(normalised to sum 1) is found by Hunter's minorisation-maximisation update

    P_i <- a_i / sum_{j != i} N_ij / (P_i + P_j),   a_i = sum_j W_ij,  N_ij = W_ij + W_ji,

which increases the likelihood every step and converges to the unique maximum whenever it exists
(Hunter's Assumption 1: in every split of the conditions into two groups, some condition of each
group beats some condition of the other).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class BradleyTerryFit:
    """A fitted Bradley-Terry model.

    ``p``: win probabilities P_i (sum 1); ``wins``: a_i (row sums of the win matrix);
    ``iterations``: MM steps taken; ``converged``: the last step changed no P_i by more than the
    tolerance; ``log_likelihood``: natural-log likelihood of the win matrix under ``p``.
    """

    conditions: tuple[str, ...]
    p: np.ndarray
    wins: np.ndarray
    iterations: int
    converged: bool
    log_likelihood: float

    def as_dict(self) -> dict[str, float]:
        """``{condition: P_i}``."""
        return {c: float(v) for c, v in zip(self.conditions, self.p, strict=True)}


def check_win_matrix(wins: np.ndarray) -> np.ndarray:
    """Validate a square, finite, non-negative win matrix and return it as float with a zero
    diagonal (self-comparisons carry no information); raise ``ValueError`` otherwise."""
    w = np.asarray(wins, dtype=float)
    if w.ndim != 2 or w.shape[0] != w.shape[1]:
        raise ValueError(f"win matrix must be square, got shape {w.shape}")
    if w.shape[0] < 2:
        raise ValueError("win matrix needs at least 2 conditions")
    if not np.all(np.isfinite(w)):
        raise ValueError("win matrix has non-finite entries")
    if np.any(w < 0):
        raise ValueError("win matrix has negative entries")
    w = w.copy()
    np.fill_diagonal(w, 0.0)
    return w


def _strongly_connected(w: np.ndarray) -> bool:
    """Hunter's Assumption 1: the directed graph i -> j (i beat j at least fractionally) is
    strongly connected, so no group of conditions loses every comparison with the rest."""
    g = w.shape[0]
    adj = w > 0
    for graph in (adj, adj.T):
        seen = {0}
        stack = [0]
        while stack:
            i = stack.pop()
            for j in np.flatnonzero(graph[i]):
                if j not in seen:
                    seen.add(int(j))
                    stack.append(int(j))
        if len(seen) != g:
            return False
    return True


def log_likelihood(wins: np.ndarray, p: np.ndarray) -> float:
    """Natural-log Bradley-Terry likelihood ``sum_ij W_ij ln(P_i / (P_i + P_j))``."""
    w = check_win_matrix(wins)
    p = np.asarray(p, dtype=float)
    ratio = p[:, None] / (p[:, None] + p[None, :])
    mask = w > 0
    return float(np.sum(w[mask] * np.log(ratio[mask])))


def fit_bradley_terry(
    wins: np.ndarray,
    conditions: list[str] | tuple[str, ...] | None = None,
    tol: float = 1e-12,
    max_iter: int = 100_000,
) -> BradleyTerryFit:
    """Fit P_i by Hunter's MM algorithm.

    ``wins[i, j]``: how often condition ``i`` was preferred over ``j`` (fractions allowed).
    ``tol``: stop when no P_i changes by more than this in one step. Raises ``ValueError`` for a
    malformed matrix or when no finite maximum-likelihood estimate exists (some group of conditions
    never wins against the others, so its P_i would go to 0).
    """
    w = check_win_matrix(wins)
    g = w.shape[0]
    if conditions is None:
        conditions = tuple(f"c{i}" for i in range(g))
    conditions = tuple(str(c) for c in conditions)
    if len(conditions) != g:
        raise ValueError(f"{len(conditions)} condition names for a {g}x{g} win matrix")
    if not _strongly_connected(w):
        raise ValueError(
            "no finite Bradley-Terry estimate: some group of conditions never wins against the "
            "others (Hunter's Assumption 1); collect more comparisons"
        )
    a = w.sum(axis=1)
    n = w + w.T
    p = np.full(g, 1.0 / g)
    converged = False
    it = 0
    for it in range(1, max_iter + 1):  # noqa: B007 - the count is reported
        denom = (n / (p[:, None] + p[None, :])).sum(axis=1)
        new = a / denom
        new /= new.sum()
        change = float(np.max(np.abs(new - p)))
        p = new
        if change <= tol:
            converged = True
            break
    return BradleyTerryFit(
        conditions=conditions,
        p=p,
        wins=a,
        iterations=it,
        converged=converged,
        log_likelihood=log_likelihood(w, p),
    )
