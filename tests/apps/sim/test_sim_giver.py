"""The simulated giver reaches with a bell-shaped (minimum-jerk) speed profile and follows the
handover's order: reach, offer, share, let go, retreat."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.sim.giver import GiverPlan, GiverState, SimulatedGiver
from gazebot.apps.sim.motion import MinJerkSegment
from gazebot.apps.sim.scene_config import GiverConfig

REST = np.array([1.0, 0.05, 1.0])
OFFER = np.array([0.75, 0.0, 1.05])


def _giver(reach=1.0, transfer=0.5, retreat=1.0, start=0.5):
    return SimulatedGiver(REST, OFFER, GiverPlan(start, reach, transfer, retreat))


def test_reach_speed_is_bell_shaped():
    giver, dt = _giver(reach=1.0, start=0.5), 1 / 240
    times = np.arange(0.0, 2.0, dt)
    hands = []
    for t in times:
        giver.update(t, robot_grasped=False)
        hands.append(giver.hand.copy())
    speed = np.linalg.norm(np.diff(hands, axis=0), axis=1) / dt
    mid = (times[1:] + times[:-1]) / 2
    moving = (mid > 0.5) & (mid < 1.5)
    s, tm = speed[moving], mid[moving]
    peak = int(np.argmax(s))
    assert tm[peak] == pytest.approx(1.0, abs=0.02)  # peak at half the reach
    assert s[0] < 0.02 * s[peak] and s[-1] < 0.02 * s[peak]  # starts and ends at rest
    assert np.all(np.diff(s[: peak + 1]) >= -1e-9) and np.all(np.diff(s[peak:]) <= 1e-9)
    # Minimum jerk: peak speed 1.875 x the mean speed.
    dist = np.linalg.norm(OFFER - REST)
    assert s[peak] == pytest.approx(1.875 * dist / 1.0, rel=0.01)
    assert np.all(speed[mid < 0.5] == 0) and np.allclose(hands[-1], OFFER)


def test_giver_waits_for_the_grasp_then_shares_lets_go_and_retreats():
    giver = _giver(reach=1.0, transfer=0.5, retreat=1.0, start=0.0)
    giver.update(1.5, robot_grasped=False)
    assert giver.state is GiverState.OFFER and giver.holds_object
    giver.update(3.0, robot_grasped=False)  # no grasp, no letting go
    assert giver.state is GiverState.OFFER
    giver.update(3.1, robot_grasped=True)
    assert giver.state is GiverState.SHARE and giver.holds_object
    giver.update(3.5, robot_grasped=True)
    assert giver.state is GiverState.SHARE
    giver.update(3.61, robot_grasped=True)
    assert giver.state is GiverState.RETREAT and not giver.holds_object
    assert giver.released_at == pytest.approx(3.61)
    giver.update(5.0, robot_grasped=True)
    assert giver.state is GiverState.DONE and np.allclose(giver.hand, REST)


def test_plan_draws_seeded_human_like_durations():
    cfg = GiverConfig()
    plans = [GiverPlan.draw(cfg, np.random.default_rng(s)) for s in range(50)]
    assert GiverPlan.draw(cfg, np.random.default_rng(3)) == plans[3]
    reach = np.array([p.reach_s for p in plans])
    assert reach.min() >= cfg.reach.min_s and reach.max() <= cfg.reach.max_s
    assert 0.8 < reach.mean() < 1.2 and reach.std() > 0.1  # seed: 0.99 +- 0.24 s
    starts = np.array([p.start_t for p in plans])
    assert np.all(np.abs(starts - cfg.start_delay_s) <= cfg.start_jitter_s)


def test_min_jerk_rejects_a_non_positive_duration():
    with pytest.raises(ValueError, match="duration"):
        MinJerkSegment(REST, OFFER, 0.0, 0.0)


def test_receiver_takes_the_object_holds_after_release_and_retreats():
    from gazebot.apps.sim.giver import GiverPlan
    from gazebot.apps.sim.receiver import ReceiverState, SimulatedReceiver

    plan = GiverPlan(start_t=0.0, reach_s=1.0, transfer_s=0.5, retreat_s=1.0)
    rest, offer = np.array([1.2, 0.0, 1.0]), np.array([0.8, 0.0, 1.1])
    person = SimulatedReceiver(rest, offer, plan, cued=True)
    person.update(0.5, object_near=False, robot_released=False)
    assert person.state is ReceiverState.IDLE  # waits for the robot's cue
    person.respond_at(0.5)
    person.update(1.0, False, False)
    assert person.state is ReceiverState.REACH and person.reach_started_at == 0.5
    person.update(1.6, False, False)
    assert person.state is ReceiverState.WAIT and np.allclose(person.hand, offer)
    person.update(1.7, True, False)
    assert person.state is ReceiverState.SHARE and person.holds_object
    person.update(1.9, True, True)
    assert person.state is ReceiverState.HOLD
    person.update(2.5, True, True)
    assert person.state is ReceiverState.RETREAT
    person.update(3.5, True, True)
    assert person.state is ReceiverState.DONE and np.allclose(person.hand, rest)
