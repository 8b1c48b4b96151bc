"""The reach-onset lower bound (benchmarks/reach_bound.py): a fidget of the generator's class is
never separated from that class (else the bound would not be one), a reach is, more evidence
comes later, and on the synthetic set the bound's median lies above issue 20's 150 ms."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from benchmarks.reach_bound import bound_latencies, fidget_residual
from gazebot.core.minimum_jerk import minimum_jerk
from gazebot.core.phases.synthetic import (
    FIDGET_AMPLITUDE,
    FIDGET_DURATION,
    SyntheticOptions,
    generate,
    synthetic_set,
)


@pytest.mark.parametrize("duration", [FIDGET_DURATION[0], 0.37, FIDGET_DURATION[1]])
def test_a_fidget_of_the_class_stays_within_one_noise_variance(duration):
    t = np.arange(0.0, 1.5, 1.0 / 240.0)
    way = np.array([-0.6, 0.5, 0.62])
    x = np.array([1.0, -0.2, 0.9]) + minimum_jerk((t - 0.513) / duration)[:, None] * (
        FIDGET_AMPLITUDE[1] * way / np.linalg.norm(way)
    )
    for end in (0.6, 0.75, 1.0, 1.5):  # during the fidget and after it
        k = t <= end
        # 1 mm of noise: the smallest in the synthetic set is 0.5 mm
        assert fidget_residual(t[k], x[k]) / 1e-3**2 < 1.0, end


def test_a_reach_is_separated_and_a_higher_bar_comes_later():
    case = generate(3, SyntheticOptions(rate=120.0, noise=0.002))
    low, high = bound_latencies(case, 1.0)[0], bound_latencies(case, 9.0)[0]
    assert 0.0 < low < high < 0.8
    # more noise: later
    noisy = replace(case, options=replace(case.options, noise=0.005))
    assert bound_latencies(noisy, 9.0)[0] > high


def test_the_synthetic_sets_bound_is_above_150_ms():
    # Issue 20 asks for a 150 ms median with no false reach on these fidgets: even the ideal
    # observer, one noise variance from every fidget, needs more (measured 167 ms, p90 255).
    lat = [x for c in synthetic_set(40, seed=7) for x in bound_latencies(c, 1.0)]
    assert np.median(lat) > 0.150
    assert np.percentile(lat, 90) > 0.250
