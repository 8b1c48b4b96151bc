"""Issue 33's careful handovers: the hands meet 0.31-0.37 m apart (segment origins of a mocap
suit, the object between), move the object together for 1.1-1.5 s (common motion 0.06-0.21
m/s) while the pair turns (relative speed 0.04-0.10 m/s at a distance held within 1 cm), then
part; frozen repeated samples and one-sample glitches of 1.5-7 cm. Pins the generator's shape of
those cases, the coupled transfer found on them offline and online, and the glitch filter."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.degrade import degraded
from gazebot.core.phases import PhaseConfig, Trajectory, compute_signals, run_online, segment
from gazebot.core.phases.filtering import drop_glitches
from gazebot.core.phases.synthetic import COUPLED_KINDS, case_set
from gazebot.core.types import EventKind, Phase

WITHIN = 0.2  # s, the issue's bar at both ends of the transfer


@pytest.fixture(scope="module")
def cases():
    return {kind: case_set(kind, 12, seed=1) for kind in COUPLED_KINDS}


def test_coupled_cases_look_like_the_issues_numbers(cases):
    for case in cases["coupled"]:
        h = case.truth[0]
        s = compute_signals(case.trajectory, PhaseConfig())
        i = int(np.searchsorted(s.t, h.transfer_start))
        m = (s.t > h.transfer_start + 0.1) & (s.t < h.transfer_end - 0.05)
        common = np.linalg.norm(s.giver_v + s.receiver_v, axis=1)[m] / 2
        assert 1.1 <= h.transfer_end - h.transfer_start <= 1.7
        assert 0.30 <= s.distance[i] <= 0.38  # segment origins, the object between
        assert np.nanmax(s.distance[m]) - np.nanmin(s.distance[m]) < 0.01
        assert 0.06 <= np.nanmedian(common) <= 0.22
        assert 0.04 <= np.nanmedian(s.rel_speed[m]) <= 0.11
        assert case.options.frozen_per_s > 0 and case.options.glitches_per_s > 0
    for case in cases["coupled30"]:
        assert np.median(np.diff(case.trajectory.t)) == pytest.approx(1 / 30, rel=0.15)
        assert case.options.noise == case.options.gripper_noise == 0.005


def _hits(group):
    """How many cases give one transfer within WITHIN of the truth at both ends, offline and
    online (the transfer_started / retreat_started events)."""
    offline = online = 0
    for case in group:
        h, tr = case.truth[0], case.trajectory
        segs = [s for s in segment(tr, PhaseConfig()) if s.phase is Phase.TRANSFER]
        offline += len(segs) == 1 and (
            abs(segs[0].start - h.transfer_start) <= WITHIN
            and abs(segs[0].end - h.transfer_end) <= WITHIN
        )
        events = run_online(tr).events
        start = [e.t for e in events if e.kind is EventKind.TRANSFER_STARTED]
        end = [e.t for e in events if e.kind is EventKind.RETREAT_STARTED]
        online += len(start) == len(end) == 1 and (
            abs(start[0] - h.transfer_start) <= WITHIN and abs(end[0] - h.transfer_end) <= WITHIN
        )
    return offline, online


def test_the_coupled_transfer_spans_the_whole_hold_at_120_hz(cases):
    # Measured 12 / 12 of 12 offline / online. A giver who leads the parting is told by how
    # far each hand has moved since the back-dated release, not by their velocities at the
    # sample seen parted (by then the receiver, setting off 0.15-0.4 s after the giver, is the
    # faster): over seeds 1-3 the ends' median error went from +0.05 s to +0.01 s.
    offline, online = _hits(cases["coupled"])
    assert offline == 12 and online == 12


def test_the_coupled_transfer_at_30_hz_with_5_mm_noise(cases):
    # Measured 10 / 11 of 12 offline / online (seeds 2-5: 11 / 10, 12 / 12, 12 / 10, 12 / 12;
    # 9 / 10, 11 / 10, 12 / 12, 12 / 10, 9 / 10 before a hold was coupled by its travel and
    # young holds confirmed; 8 / 9, 11 / 9, 10 / 11, 10 / 9, 9 / 10 before the giver's
    # departure, the turning merge and the stop in a gap); the misses: starts 0.2-0.33 s off
    # where the pair's turning keeps the relative speed above the hold's floor at contact,
    # online starts 0.2-0.28 s early (confirmed on the approach's slow tail), a receiver-led
    # parting inside the noise band, and online ends 0.23-0.39 s late (a parting confirmed a
    # window later, or dated at a tracking gap). The issue's target is 12 of 12: not
    # reached. Pinned against regressions.
    offline, online = _hits(cases["coupled30"])
    assert offline >= 10 and online >= 11


def test_the_coupled_transfer_at_120_hz_on_more_recordings():
    # Seeds 2-5 (48 more recordings): measured 48 / 48 of 48 offline / online (the online
    # miss of seed 4, case 7, ended 1.3 s early before young holds were confirmed).
    offline = online = 0
    for seed in (2, 3, 4, 5):
        off, on = _hits(case_set("coupled", 12, seed=seed))
        offline, online = offline + off, online + on
    assert offline == 48 and online == 48


def _transfers(case):
    return [s for s in segment(case.trajectory, PhaseConfig()) if s.phase is Phase.TRANSFER]


def _online_ends(case):
    events = run_online(case.trajectory).events
    return [e.t for e in events if e.kind is EventKind.RETREAT_STARTED]


def test_pressing_the_object_in_is_no_release():
    # The giver pushes the object toward a receiver whose marker lags (the distance shrinks
    # 1.6 cm below the held one at 0.13 m/s): online this ended the transfer 1.0 s early.
    case = case_set("coupled30", 12, seed=5)[0]
    ends = _online_ends(case)
    assert len(ends) == 1 and abs(ends[0] - case.truth[0].transfer_end) <= WITHIN


@pytest.mark.parametrize("seed, k", [(3, 0), (1, 2), (1, 5), (5, 2), (5, 4)])
def test_a_carried_object_is_not_released_early_online(seed, k):
    # 30 Hz, 5 mm noise: while the pair carries the object, one marker lags or the newest
    # samples (smoothed from one side) part the hands for a few samples. Online these ended
    # the transfer 0.55-1.22 s early; hands that moved the object together are parted only if
    # no nearer a smoothing window later (they now end 0.00 to +0.24 s from the truth).
    case = case_set("coupled30", 12, seed=seed)[k]
    ends = _online_ends(case)
    assert len(ends) == 1 and ends[0] >= case.truth[0].transfer_end - WITHIN


def test_hands_carried_into_a_gap_at_the_newest_sample_are_not_released():
    # The receiver's marker is lost while both hands carry the object: the giver's motion is
    # the pair's (online this ended the transfer 1.06 s early).
    case = case_set("coupled30", 12, seed=5)[8]
    ends = _online_ends(case)
    assert len(ends) == 1 and abs(ends[0] - case.truth[0].transfer_end) <= WITHIN


def test_a_glitch_at_the_closest_point_does_not_lose_the_transfer():
    # A marker glitch makes the minimum distance a run too short to be a transfer: the
    # longest run is the core (this recording had no transfer at all).
    case = case_set("coupled30", 12, seed=5)[6]
    segs = _transfers(case)
    assert len(segs) == 1 and abs(segs[0].start - case.truth[0].transfer_start) <= WITHIN


def test_a_hold_across_a_tracking_gap_is_one_transfer_from_the_meeting():
    # The pair turns on after a 0.3 s gap a little over the exit speed's blip length: the
    # transfer still starts at the meeting (it started 0.97 s late).
    case = case_set("coupled30", 12, seed=2)[7]
    segs = _transfers(case)
    assert len(segs) == 1 and abs(segs[0].start - case.truth[0].transfer_start) <= WITHIN


def test_a_one_sample_glitch_is_dropped_and_a_real_step_kept():
    t = np.arange(0.0, 1.0, 1 / 120)
    p = np.zeros((t.size, 3))
    p[:, 0] = 0.1 * t  # a hand moving at 0.1 m/s
    p[40, 1] += 0.05  # a glitch of 5 cm for one sample
    p[80:, 2] += 0.06  # the marker slips 6 cm for good
    bad = drop_glitches(t, p, 0.03, np.ones(t.size, dtype=bool))
    assert bad.nonzero()[0].tolist() == [40, 80]  # the step's first sample only


def test_noise_alone_is_no_glitch():
    rng = np.random.default_rng(3)
    for rate, noise in ((30.0, 0.005), (120.0, 0.005), (8.0, 0.003)):
        t = np.arange(0.0, 20.0, 1 / rate)
        p = 0.3 * np.sin(t)[:, None] * [1.0, 0.5, 0.2] + rng.normal(0, noise, (t.size, 3))
        bad = drop_glitches(t, p, PhaseConfig().glitch_jump, np.ones(t.size, dtype=bool))
        assert bad.sum() <= 0.002 * t.size, (rate, noise, int(bad.sum()))


@pytest.mark.parametrize("seed, k", [(8, 7), (1, 5), (9, 10)])
def test_a_pair_carrying_the_object_while_one_hand_is_hidden_keeps_holding(seed, k):
    # The giver's marker is lost for 0.3 s while the pair carries the object at up to 0.36
    # m/s; the hands part by a centimetre just before (the receiver moving on first), then
    # are back at the held distance, the pair turned 3.5 cm. The check a smoothing window
    # later fell in the gap and let the parting stand: the transfer ended 1.13 s early (0.11-
    # 0.14 s in the other two). It is judged after the gap, by the distance, and the hold is
    # taken on over all of it.
    case = case_set("coupled30", 12, seed=seed)[k]
    segs = _transfers(case)
    assert len(segs) == 1 and abs(segs[0].end - case.truth[0].transfer_end) <= 0.1


def test_online_a_receiver_carrying_across_the_line_as_the_givers_marker_is_lost_holds():
    # The pair carries the object (the receiver at 0.25 m/s, mostly across the hands' line)
    # while the giver's marker lags, then is lost for 0.3 s: nothing is seen a smoothing window
    # after the parting yet, so it stood and the release was reported 1.12 s early. With the
    # receiver leading a parting across the line into a gap, the hold waits for data.
    case = case_set("coupled30", 12, seed=8)[7]
    ends = _online_ends(case)
    assert len(ends) == 1 and abs(ends[0] - case.truth[0].transfer_end) <= WITHIN


def test_online_a_giver_moving_toward_the_lost_receiver_is_not_withdrawing():
    # The receiver's marker is lost to the newest sample while the giver moves the object at
    # 0.15 m/s toward where the receiver was (the pair carrying it): the giver's motion was
    # taken as its withdrawal and the release reported 1.19 s early.
    case = case_set("coupled30", 12, seed=7)[4]
    ends = _online_ends(case)
    assert len(ends) == 1 and abs(ends[0] - case.truth[0].transfer_end) <= WITHIN


@pytest.mark.parametrize("seed, k", [(1, 2), (3, 0)])
def test_a_giver_led_parting_starts_at_the_givers_last_speed_minimum(seed, k):
    # The giver sets off across the hands' line, their distance unchanged for 0.2 s: dated
    # from the distance alone the release was 0.21 s late.
    case = case_set("coupled30", 12, seed=seed)[k]
    segs = _transfers(case)
    assert len(segs) == 1 and abs(segs[0].end - case.truth[0].transfer_end) <= WITHIN


@pytest.mark.parametrize("seed, k", [(10, 0), (6, 2)])
def test_the_pair_turning_between_two_holds_does_not_split_the_transfer(seed, k):
    # At 30 Hz the careful pair's turn reads over 20 cm/s of relative motion across their line
    # for a tenth of a second between two holds: the transfer started at the second hold,
    # 0.25-1.3 s late.
    case = case_set("coupled30", 12, seed=seed)[k]
    segs = _transfers(case)
    assert len(segs) == 1 and abs(segs[0].start - case.truth[0].transfer_start) <= WITHIN


@pytest.mark.parametrize("seed, k", [(7, 9), (10, 10)])
def test_a_hold_regripped_faster_than_the_seeds_speed_is_one_transfer_from_the_meeting(seed, k):
    # At 30 Hz with 5 mm noise a hand adjusts its grip, or the pair presses the object in,
    # faster than the seed's 15 cm/s for 0.2-0.5 s between two holds, the distance within 2
    # cm and mostly along the hands' line (no turn): the transfer started at the later hold,
    # 0.36-0.62 s late.
    case = case_set("coupled30", 12, seed=seed)[k]
    segs = _transfers(case)
    assert len(segs) == 1 and abs(segs[0].start - case.truth[0].transfer_start) <= WITHIN


def test_a_transfer_regripped_at_the_closest_point_contains_it():
    # The hold around the minimum distance is shorter than min_transfer (a regrip on either
    # side of it): the longest hold, after it, was the core and the transfer started 0.70 s
    # late, after the minimum distance (the issue's held-out failure). Measured: 0.24 s early.
    case = case_set("coupled30", 12, seed=10)[2]
    segs = _transfers(case)
    s = compute_signals(case.trajectory, PhaseConfig())
    closest = float(s.t[np.nanargmin(s.distance)])
    assert len(segs) == 1 and segs[0].start <= closest <= segs[0].end
    assert abs(segs[0].start - case.truth[0].transfer_start) <= 0.3


def _ease(t, t0, t1, x0, x1):
    u = np.clip((t - t0) / (t1 - t0), 0.0, 1.0)
    return x0 + (x1 - x0) * (10 * u**3 - 15 * u**4 + 6 * u**5)


def test_an_approach_that_paused_short_of_contact_is_no_regrip():
    # The receiver stops 4 cm short for 0.4 s, then closes in (peak 0.375 m/s): its pause is
    # no hold of the object, so the transfer starts at the final hold (measured 2.71 s), not at
    # the pause (2.06 s, as it would if any two holds with a careful common motion merged).
    t = np.arange(0.0, 5.0, 1 / 120)
    giver = np.zeros((t.size, 3))
    giver[:, 0] = _ease(t, 0.8, 1.8, -0.2, 0.0)
    receiver = np.zeros((t.size, 3))
    receiver[:, 0] = (
        _ease(t, 1.0, 2.0, 1.2, 0.39)
        + _ease(t, 2.4, 2.6, 0.0, -0.04)
        + _ease(t, 3.8, 4.8, 0.0, 0.8)
    )
    segs = [
        s
        for s in segment(Trajectory(t, giver, receiver), PhaseConfig())
        if s.phase is Phase.TRANSFER
    ]
    assert len(segs) == 1 and 2.4 <= segs[0].start <= 2.8


@pytest.mark.parametrize("seed, k", [(3, 10), (4, 7)])
def test_an_approach_that_stops_in_a_tracking_gap_before_the_pair_turns(seed, k):
    # The meeting hides in a tracking gap and the pair is turning the object when the markers
    # return (relative speed over the settle speed, their speed against their common motion
    # under it): the start is dated from the approach seen before the gap, not from the turn's
    # first lull (0.23-0.83 s late).
    case = case_set("coupled30", 12, seed=seed)[k]
    segs = _transfers(case)
    assert len(segs) == 1 and abs(segs[0].start - case.truth[0].transfer_start) <= WITHIN


@pytest.mark.parametrize("k", [3, 9])
def test_a_careful_pair_slowing_into_the_release_is_coupled_by_its_travel(k):
    # The pair carries the object 9-15 cm over the hold, slowing between two legs and into
    # the release: the common motion's median is 5.6-5.7 cm/s, under coupled_speed, so the
    # hold was judged by its relative position (the pair turning) and the release held to
    # the last still sample, 0.24-0.28 s late offline and online. The midpoint's travel
    # (coupled_travel) makes it coupled; a still hold's 5 mm noise moves it 0.5 cm.
    case = case_set("coupled30", 12, seed=5)[k]
    segs = _transfers(case)
    assert len(segs) == 1 and abs(segs[0].end - case.truth[0].transfer_end) <= WITHIN
    ends = _online_ends(case)
    assert len(ends) == 1 and abs(ends[0] - case.truth[0].transfer_end) <= WITHIN


@pytest.mark.parametrize("kind, seed, k", [("coupled", 4, 7), ("coupled30", 4, 3)])
def test_a_hold_just_confirmed_is_not_released_by_its_first_samples_online(kind, seed, k):
    # Online, 0.05-0.13 s after the transfer was confirmed, the pair sets off with one marker
    # lagging; smoothed from one side, the newest samples part the hands by 1.3 cm. The
    # release was reported 1.16-1.32 s early; a hold younger than young_hold has parted
    # only if the hands are no nearer a smoothing window later.
    case = case_set(kind, 12, seed=seed)[k]
    ends = _online_ends(case)
    assert len(ends) == 1 and ends[0] >= case.truth[0].transfer_end - WITHIN


def _degraded(case, seed):
    # 120 -> 30 Hz, four dropouts of 0.05-0.2 s per hand, 5 mm of noise and a 6 cm marker
    # offset, all at once (the held-out recordings' degraded copies)
    return degraded(case.trajectory, "all", np.random.default_rng(seed))


@pytest.mark.parametrize("seed, k, copy", [(3, 4, 3040), (3, 10, 3102)])
def test_the_pair_turning_faster_than_the_exit_speed_between_two_holds_merges_them(seed, k, copy):
    # Degraded to 30 Hz with 5 mm noise, the pair carrying the object reads a common motion
    # of 0.2-0.3 m/s and a relative speed just over the exit speed for a few samples between
    # two holds, at a distance held within 1 cm: under turning_common_max (0.4 m/s) the holds
    # merge. With the exit speed as the bar the transfer ended 1.14 s and 0.26 s early.
    case = case_set("coupled", 12, seed=seed)[k]
    segs = [s for s in segment(_degraded(case, copy), PhaseConfig()) if s.phase is Phase.TRANSFER]
    truth = case.truth[0]
    assert len(segs) == 1
    assert abs(segs[0].start - truth.transfer_start) <= WITHIN
    assert abs(segs[0].end - truth.transfer_end) <= WITHIN


def test_a_bounce_at_the_meeting_is_no_release():
    # Degraded to 30 Hz with 5 mm noise and 6 cm marker offsets, the hands meet 1.2 cm nearer
    # than they then hold (the closest point), part along their line at up to 0.2 m/s for 0.1
    # s and carry the object together for 0.9 s: the 0.1 s hold at the closest point was the
    # transfer, ending 1.13 s early. A hold younger than young_hold that the hands leave and
    # hold again within the regrip band goes on into the next hold.
    case = case_set("coupled", 12, seed=3)[5]
    segs = [s for s in segment(_degraded(case, 3050), PhaseConfig()) if s.phase is Phase.TRANSFER]
    truth = case.truth[0]
    assert len(segs) == 1
    assert abs(segs[0].start - truth.transfer_start) <= WITHIN
    assert abs(segs[0].end - truth.transfer_end) <= WITHIN
