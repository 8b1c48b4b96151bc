"""The one minimum-jerk profile: its formula, its ends, its peak rate, and the same values for a
float and an array."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.core.minimum_jerk import PEAK_RATE, minimum_jerk, minimum_jerk_rate


def test_the_profile_is_the_quintic_10s3_15s4_6s5():
    s = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(minimum_jerk(s), 10 * s**3 - 15 * s**4 + 6 * s**5, atol=1e-15)


def test_the_profile_holds_its_ends_outside_the_move():
    assert minimum_jerk(-0.3) == 0.0 and minimum_jerk(0.0) == 0.0
    assert minimum_jerk(1.0) == 1.0 and minimum_jerk(7.0) == 1.0
    assert minimum_jerk(0.5) == 0.5
    np.testing.assert_array_equal(minimum_jerk(np.array([-1.0, 2.0])), [0.0, 1.0])
    assert math.isnan(minimum_jerk(math.nan))


def test_the_rate_is_the_profiles_derivative_and_peaks_at_the_middle():
    s = np.linspace(0.0, 1.0, 2001)
    np.testing.assert_allclose(minimum_jerk_rate(s), np.gradient(minimum_jerk(s), s), atol=1e-5)
    assert minimum_jerk_rate(0.5) == PEAK_RATE == float(minimum_jerk_rate(s).max())
    assert minimum_jerk_rate(0.0) == minimum_jerk_rate(1.0) == minimum_jerk_rate(3.0) == 0.0


@pytest.mark.parametrize("f", [minimum_jerk, minimum_jerk_rate])
def test_a_float_and_an_array_give_the_same_values(f):
    s = np.random.default_rng(0).uniform(-0.5, 1.5, 50)
    assert f(s).tolist() == [f(float(v)) for v in s]
    assert isinstance(f(0.25), float)
