"""The blink model: natural rate with jitter, blinks with large gaze shifts, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.core.runtime.blink import BlinkConfig, BlinkModel

DT = 1.0 / 50.0


def run(model: BlinkModel, seconds: float, shift=lambda t: 0.0) -> np.ndarray:
    ts = np.arange(0.0, seconds, DT)
    return np.array([model.update(t, shift(t)) for t in ts])


def test_spontaneous_rate_is_15_to_20_per_minute_with_jitter():
    model = BlinkModel(seed=0)
    run(model, 600.0)
    per_min = model.blinks / 10.0
    assert 14.0 <= per_min <= 21.0
    intervals = np.diff(model.blink_times)
    assert intervals.min() >= model.config.min_interval_s - DT
    cv = intervals.std() / intervals.mean()
    assert 0.2 < cv < 0.9  # irregular, unlike a metronome


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_rate_holds_for_other_seeds(seed):
    model = BlinkModel(seed=seed)
    run(model, 300.0)
    assert 12.0 <= model.blinks / 5.0 <= 23.0


def test_blink_values_stay_in_0_1_and_a_blink_closes_fully():
    values = run(BlinkModel(seed=4), 60.0)
    assert values.min() >= 0.0 and values.max() <= 1.0
    assert values.max() == 1.0
    assert (values == 0.0).mean() > 0.8  # eyes are open most of the time


def test_same_seed_gives_the_same_blinks_and_other_seeds_differ():
    a, b, c = BlinkModel(seed=7), BlinkModel(seed=7), BlinkModel(seed=8)
    va, vb, vc = run(a, 60.0), run(b, 60.0), run(c, 60.0)
    assert np.array_equal(va, vb)
    assert a.blink_times == b.blink_times
    assert a.blink_times != c.blink_times
    assert not np.array_equal(va, vc)


def test_reset_replays_the_same_sequence():
    m = BlinkModel(seed=5)
    first = run(m, 30.0)
    m.reset()
    assert np.array_equal(first, run(m, 30.0))


def test_large_gaze_shifts_usually_trigger_a_blink_at_once():
    m = BlinkModel(seed=0, config=BlinkConfig(rate_per_min=2.0))  # rare spontaneous blinks
    evoked = 0
    for k in range(40):
        t0 = 5.0 * k
        m.update(t0 - 0.5, 0.0)
        before = m.blinks
        m.update(t0, math.radians(40))
        evoked += m.blinks > before and m.blink_times[-1] == t0
    assert evoked >= 30


def test_a_quick_run_of_small_steps_counts_as_one_large_shift():
    m = BlinkModel(seed=1, config=BlinkConfig(rate_per_min=2.0, shift_probability=1.0))
    m.update(0.0, 0.0)
    for i in range(1, 8):  # 35 degrees over ~0.12 s
        m.update(i * 0.0167, math.radians(5))
    assert m.blinks == 1


def test_slow_pursuit_and_small_shifts_do_not_add_blinks():
    base = BlinkModel(seed=2)
    run(base, 120.0)
    pursuit = BlinkModel(seed=2)
    run(pursuit, 120.0, shift=lambda t: 0.3 * DT)  # 0.3 rad/s smooth pursuit
    assert pursuit.blinks == base.blinks


@pytest.mark.parametrize("t,shift", [(math.nan, 0.0), (0.0, math.inf), (math.inf, 0.0)])
def test_non_finite_inputs_raise_value_error(t, shift):
    with pytest.raises(ValueError, match="must be finite"):
        BlinkModel().update(t, shift)


def test_time_going_backwards_raises_value_error():
    m = BlinkModel()
    m.update(1.0)
    with pytest.raises(ValueError, match="backwards"):
        m.update(0.5)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"rate_per_min": 0.0},
        {"shift_probability": 1.5},
        {"close_s": math.nan},
        {"rate_per_min": 100.0, "min_interval_s": 1.0},
    ],
)
def test_bad_config_raises_value_error(kwargs):
    with pytest.raises(ValueError, match="BlinkConfig"):
        BlinkConfig(**kwargs)


def test_absurd_shifts_count_as_a_half_turn_and_shift_blinks_come_back():
    """Finite but absurd shifts (1e308 rad: a corrupted command) count as pi: the decayed sum
    stays finite, so after a long still stretch a large shift evokes blinks again (an
    overflowing sum would decay to NaN and disarm the shift rule for good)."""
    cfg = BlinkConfig(rate_per_min=2.0, shift_probability=1.0)
    m = BlinkModel(seed=0, config=cfg)
    m.update(0.0, 1e308)
    m.update(0.01, -1e308)
    m.update(1e6, 0.0)  # a very long gap: the sum decays to nothing
    before = m.blinks
    m.update(1e6 + 5.0, math.radians(40))
    assert m.blinks == before + 1 and m.blink_times[-1] == 1e6 + 5.0
