"""``rules.transfer.dips`` (leg by leg, with running extrema) finds the dips the sample-by-sample
zigzag finds, index for index."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.core.phases.rules.transfer import dips


def _dips_by_sample(d: np.ndarray, depth: float) -> list[tuple[int, int, int]]:
    """The zigzag one sample at a time (the rule's definition, as it was written first)."""
    out: list[tuple[int, int, int]] = []
    idx = np.isfinite(d).nonzero()[0]
    if idx.size == 0:
        return out
    left = int(idx[0])
    going_down = True
    lo_v, lo_i = math.inf, -1
    hi_v, hi_i = -math.inf, -1
    for i, v in zip(idx.tolist(), d[idx].tolist(), strict=True):
        if going_down:
            if v < lo_v:
                lo_v, lo_i = v, i
            elif v >= lo_v + depth:
                going_down = False
                hi_v, hi_i = v, i
        else:
            if v > hi_v:
                hi_v, hi_i = v, i
            elif v <= hi_v - depth:
                out.append((left, lo_i, hi_i))
                left = hi_i
                going_down = True
                lo_v, lo_i = v, i
    if going_down:
        if lo_i >= 0:
            out.append((left, lo_i, int(idx[-1])))
    else:
        out.append((left, lo_i, hi_i if hi_i >= 0 else int(idx[-1])))
    return out


def test_dips_match_the_sample_by_sample_zigzag_on_walks_with_gaps_ties_and_plateaus() -> None:
    rng = np.random.default_rng(19)
    for trial in range(600):
        n = int(rng.integers(0, 120))
        step = rng.normal(0.0, 0.05, n)
        if trial % 3 == 0:
            step = np.round(step, 1)  # (plateaus and equal values: ties for the extrema)
        d = 1.0 + np.cumsum(step)
        if trial % 4 == 0 and n:
            d[rng.random(n) < 0.2] = np.nan  # tracking gaps
        if trial % 7 == 0 and n:
            d[:] = np.nan if trial % 14 == 0 else d[0]  # all unknown / all equal
        depth = float(rng.choice([0.05, 0.1, 0.2, 1e-12]))
        assert dips(d, depth) == _dips_by_sample(d, depth), (trial, d.tolist(), depth)


def test_dips_of_one_or_no_sample() -> None:
    assert dips(np.array([0.4]), 0.1) == [(0, 0, 0)] == _dips_by_sample(np.array([0.4]), 0.1)
    assert dips(np.empty(0), 0.1) == [] == _dips_by_sample(np.empty(0), 0.1)


def test_dips_need_a_positive_depth() -> None:
    with pytest.raises(ValueError, match="depth must be > 0"):
        dips(np.array([1.0, 0.5, 1.0]), 0.0)


def test_dips_match_the_zigzag_on_long_recordings_with_many_legs() -> None:
    """Legs shorter and much longer than the first search window, hundreds of them: the same
    dips (the windows double from each leg's start, so a leg's search never reads past what
    it needs by more than its own length)."""
    rng = np.random.default_rng(23)
    t = np.arange(6000) / 120.0
    for freq, noise in ((3.0, 0.002), (0.05, 0.01), (0.7, 0.0)):
        d = 0.5 + 0.3 * np.sin(2 * np.pi * freq * t) + rng.normal(0.0, noise, t.shape[0])
        d[rng.random(t.shape[0]) < 0.01] = np.nan
        for depth in (0.05, 0.2, 0.7):
            assert dips(d, depth) == _dips_by_sample(d, depth), (freq, depth)


def test_dips_of_float32_distances_are_decided_in_float64() -> None:
    """A float32 signal is compared in float64, as the zigzag's plain floats compare it."""
    rng = np.random.default_rng(29)
    for _ in range(300):
        d = (1.0 + np.cumsum(rng.normal(0.0, 0.1, 40))).astype(np.float32)
        assert dips(d, 0.2) == _dips_by_sample(d, 0.2)
    d = np.array([0.7, 0.9, 0.2], np.float32)
    assert dips(d, 0.2) == _dips_by_sample(d, 0.2)


def test_dips_of_long_double_distances_keep_their_precision() -> None:
    """A wider float signal is compared in its own precision, as the zigzag compares it."""
    d = np.array([0.9, 0.8, 0.9, 1, 1, 1, 0.9, 1], dtype=np.longdouble)
    assert dips(d, 0.1) == _dips_by_sample(d, 0.1)
