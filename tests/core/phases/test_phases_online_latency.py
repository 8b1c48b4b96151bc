"""Online latency of every event kind, and no false events on a fidgeting, noisy or aborted
giver (pins the online reach rules, smoothed and predictive, the release rule and the predicted
landing)."""

from __future__ import annotations

import numpy as np
import pytest
from phase_truth import PHASE_KINDS, event_errors

from gazebot.core.minimum_jerk import minimum_jerk
from gazebot.core.phases import Trajectory, run_online
from gazebot.core.phases.synthetic import rest_recording, synthetic_set
from gazebot.core.types import EventKind


@pytest.mark.parametrize(
    ("kind", "median", "p90", "share"),
    [
        # Median / p90, share within 250 ms. Measured 222 / 347 ms, 62 % (227 / 349 ms, 60 %
        # with the predictive rule alone, without the sequential one; 285 / 392 ms, 40 %,
        # before both: 2 cm of closing past the smoothing's edge).
        (EventKind.REACH_STARTED, 0.235, 0.35, 0.6),
        # Measured 264 / 376 ms, 35 % (1 cm of separation, or 4x the hold's jitter).
        (EventKind.RETREAT_STARTED, 0.27, 0.38, 0.33),
        # Measured -21 / 43 ms, 100 % (the predicted landing).
        (EventKind.HANDOVER_DONE, 0.0, 0.06, 1.0),
    ],
)
def test_online_latency_on_the_varied_set(varied_set, online_results, kind, median, p90, share):
    _, lat = event_errors(varied_set, online_results, kind)
    assert len(lat) == sum(len(c.truth) for c in varied_set)
    assert np.median(lat) <= median
    assert np.percentile(lat, 90) <= p90
    assert np.mean(lat <= 0.25) >= share


def test_predicted_landing_dates_the_end_of_the_retreat(varied_set, online_results):
    err, lat = event_errors(varied_set, online_results, EventKind.HANDOVER_DONE)
    # Measured |err| median 47, p90 121, max 201 ms (63 / 164 / 228 when the landing was
    # clipped to the signals' last point: dated by when the analysis ran, not the profile).
    assert np.median(err) <= 0.055 and np.percentile(err, 90) <= 0.14 and err.max() <= 0.23
    assert lat.max() <= 0.12  # never waits for a rest hold


def _rest_recording(rate, jitter, noise, seconds, seed, hand=None):
    rng = np.random.default_rng(seed)
    n = int(seconds * rate)
    t = np.cumsum((1.0 / rate) * (1.0 + rng.uniform(-jitter, jitter, n)))
    sway = 0.004 * np.sin(2 * np.pi * 0.3 * t)[:, None] * np.array([1.0, 0.5, 0.3])
    g = np.array([1.05, -0.2, 0.9]) + sway + rng.normal(0.0, noise, (n, 3))
    if hand is not None:
        g += hand(t)
    r = np.array([0.35, -0.3, 0.25]) + rng.normal(0.0, 0.0003, (n, 3))
    return Trajectory(t, g, r)


def _phase_events(traj):
    return [e for e in run_online(traj).events if e.kind in PHASE_KINDS]


@pytest.mark.parametrize("rate", [8.0, 30.0, 120.0, 240.0])
@pytest.mark.parametrize("noise", [0.002, 0.005])
def test_noisy_resting_hands_give_no_event(rate, noise):
    # 5 mm of noise shows as up to 0.3 m/s of filtered speed: the thresholds follow the noise.
    for jitter in (0.0, 0.4):
        traj = _rest_recording(rate, jitter, noise, 20.0, seed=int(rate + 1000 * noise))
        assert _phase_events(traj) == [], (rate, noise, jitter)


def test_handovers_with_5mm_noise_give_exactly_their_events():
    cases = synthetic_set(14, seed=5, noise=0.005)
    for case in cases:
        kinds = [e.kind for e in _phase_events(case.trajectory)]
        assert kinds == list(PHASE_KINDS) * len(case.truth), case.options


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_fidgeting_giver_gives_no_event(seed):
    # Small adjustments at rest: 0.8-2 cm in 0.25-0.6 s (peak speed up to 15 cm/s), any
    # direction, half of them at the receiver (the generator's fidget set, also benchmarked).
    for rate in (8.0, 30.0, 120.0, 240.0):
        traj = rest_recording(rate, 0.002, 20.0, seed=int(rate) + seed, fidget=True)
        assert _phase_events(traj) == [], rate


@pytest.mark.parametrize("rate", [8.0, 15.0, 60.0, 240.0])
def test_a_reach_taken_back_ends_as_aborted_without_transfer(rate):
    # 25 cm toward the receiver in 0.6 s, a pause, back to rest.
    target = np.array([-0.25, -0.03, -0.05])

    def hand(t):
        out = minimum_jerk((t - 2.0) / 0.6)[:, None] * target
        return out - minimum_jerk((t - 2.9) / 0.7)[:, None] * target

    traj = _rest_recording(rate, 0.3, 0.002, 6.0, seed=7, hand=hand)
    events = _phase_events(traj)
    kinds = [e.kind for e in events]
    assert kinds == [EventKind.REACH_STARTED, EventKind.HANDOVER_DONE], rate
    # 2 cm of closing takes ~0.2 s; a sparse recording shows it up to one sample later.
    assert events[0].detected_at - 2.0 <= 0.25 + 1.0 / rate
    assert events[1].info["source"] == "aborted"


def test_the_predictive_rules_confirm_a_reach_before_the_smoothed_signals():
    # The same varied handovers (120 Hz: at 8-30 Hz the model has too few samples to beat the
    # smoothed rule) with the predictive rules out of reach (predict_distance 10 m, and the
    # sequential rule's sequential_evidence 1e9): the rules confirm the reach earlier, and
    # never later on any handover.
    from gazebot.core.phases import PhaseConfig

    cases = synthetic_set(10, seed=5, rate=120.0)
    earlier = []
    for case in cases:
        got = {}
        off = PhaseConfig(predict_distance=10.0, sequential_evidence=1e9)
        for name, cfg in (("on", PhaseConfig()), ("off", off)):
            got[name] = [
                e.detected_at
                for e in run_online(case.trajectory, cfg).events
                if e.kind is EventKind.REACH_STARTED
            ]
        assert len(got["on"]) == len(got["off"]) == len(case.truth)
        earlier += [b - a for a, b in zip(got["on"], got["off"], strict=True)]
    assert min(earlier) >= -0.02  # one analysis period
    # Measured: median 25 ms, 50 % of the reaches 50-330 ms earlier.
    assert np.median(earlier) >= 0.02
    assert np.mean(np.array(earlier) >= 0.04) >= 0.4


def test_a_reach_away_from_the_receiver_is_not_predicted():
    # 25 cm away from the receiver (+x) in 0.6 s: accelerating, fast, but not toward it.
    from gazebot.core.phases import PhaseConfig
    from gazebot.core.phases.rules.directed import directed_reach

    target = np.array([0.25, 0.0, 0.0])

    def hand(t):
        return minimum_jerk((t - 2.0) / 0.6)[:, None] * target

    traj = _rest_recording(120.0, 0.0, 0.001, 2.15, seed=3, hand=hand)
    c = PhaseConfig()
    assert directed_reach(traj, c, -np.inf) is None
    toward = _rest_recording(120.0, 0.0, 0.001, 2.15, seed=3, hand=lambda t: -hand(t))
    onset = directed_reach(toward, c, -np.inf)
    assert onset is not None and abs(onset - 2.0) <= 0.06
