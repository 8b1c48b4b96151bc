"""The seed's reach controllers (chapters 3-4): speed cap, start, timing and failure feedback."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.controllers import ReachObservation, load_controllers_config, make_controller
from gazebot.apps.controllers.config import SpeedLimit, Strategy
from gazebot.apps.controllers.rollout import run_reach

HAND = np.array([1.5, 0.0, 0.0])  # 1.5 m from the start (seed Fig. 4.4 setting)
START = np.zeros(3)


def _cfg(**update):
    cfg = load_controllers_config()
    stl = cfg.stl.model_copy(update={"horizon": 15})
    return cfg.model_copy(update={"u_max_m_s": 1.0, "dt_s": 0.2, "stl": stl, **update})


@pytest.mark.parametrize("name", ["mcj", "mce", "stl"])
def test_one_second_reach_is_infeasible_and_reported(name):
    run = run_reach(make_controller(name, _cfg(reach_time_s=1.0)), START, HAND, 1.4)
    assert not run.feasible
    assert not run.feasible_steps[0]  # known at the very first plan


def test_stl_stops_when_infeasible():
    run = run_reach(make_controller("stl", _cfg(reach_time_s=1.0)), START, HAND, 1.0)
    assert np.allclose(run.velocities, 0.0)


@pytest.mark.parametrize("name", ["mcj", "mce", "stl"])
@pytest.mark.parametrize("reach_time", [2.0, 3.0])
def test_feasible_reach_ends_at_the_hand_by_the_reach_time(name, reach_time):
    cfg = _cfg(reach_time_s=reach_time)
    run = run_reach(make_controller(name, cfg), START, HAND, reach_time + 0.4)
    assert run.feasible
    k = int(round(reach_time / cfg.dt_s))
    tol = cfg.stl.eps_p_m if name == "stl" else cfg.mcj.eps_x_m
    norm = (lambda d: np.abs(d).sum()) if name == "stl" else np.linalg.norm  # stl: l1 (4.4.1)
    assert norm(run.positions[k] - HAND) <= tol + 1e-5
    # and stays there
    assert all(norm(p - HAND) <= tol + 1e-5 for p in run.positions[k:])


@pytest.mark.parametrize("name", ["pv", "mcj", "mce", "stl"])
def test_velocity_never_exceeds_the_cap_per_axis(name):
    cfg = _cfg(reach_time_s=2.0, u_max_m_s=0.9)
    run = run_reach(make_controller(name, cfg), START, np.array([1.2, -0.6, 0.3]), 2.6)
    assert np.abs(run.velocities).max() <= 0.9 + 1e-6


def test_norm_speed_limit_caps_the_euclidean_speed():
    cfg = _cfg(reach_time_s=3.0, u_max_m_s=0.8, speed_limit=SpeedLimit.NORM)
    for name in ("pv", "mcj", "mce"):
        run = run_reach(make_controller(name, cfg), START, np.array([1.0, 1.0, 0.0]), 3.0)
        assert np.linalg.norm(run.velocities, axis=1).max() <= 0.8 + 1e-6


def test_mcj_starts_at_rest():
    run = run_reach(make_controller("mcj", _cfg(reach_time_s=3.0)), START, HAND, 0.4)
    assert np.allclose(run.velocities[0], 0.0)  # eq. 3.3d
    assert run.positions[0] == pytest.approx(START)  # eq. 3.3c


def test_mce_holds_still_until_the_stall_time_then_reaches():
    cfg = _cfg(reach_time_s=2.5, stall_time_s=0.6)
    run = run_reach(make_controller("mce", cfg), START, HAND, 2.8)
    assert run.feasible
    moving = np.linalg.norm(run.velocities, axis=1) > 1e-6
    assert not moving[:3].any()  # 0.0, 0.2, 0.4 s: still (eq. 3.5)
    assert moving[3]
    assert np.linalg.norm(run.positions[int(round(2.5 / 0.2))] - HAND) <= 0.01 + 1e-5


def test_mce_stall_can_make_a_reach_infeasible():
    # 1.5 m in 2 s at 1 m/s is feasible, but not after 1 s of stalling.
    run = run_reach(
        make_controller("mce", _cfg(reach_time_s=2.0, stall_time_s=1.0)), START, HAND, 2.0
    )
    assert not run.feasible_steps[0]


def test_pv_reaches_the_hand():
    run = run_reach(make_controller("pv", _cfg()), START, HAND, 4.0)
    assert run.reached_at(0.01) is not None
    assert run.gap()[-1] < 1e-3


def test_pv_is_proportional_below_saturation():
    cfg = _cfg()
    plan = make_controller("pv", cfg).plan(
        ReachObservation(t=0.0, x=START, hand=np.array([0.1, 0, 0]))
    )
    assert plan.command == pytest.approx([cfg.pv.k_p * 0.1, 0, 0])


def test_mcj_is_smoother_than_mce():
    cfg = _cfg(reach_time_s=3.0)
    jerk = {}
    for name in ("mcj", "mce"):
        u = run_reach(make_controller(name, cfg), START, HAND, 3.0).velocities
        jerk[name] = float(np.sum(np.diff(np.vstack([np.zeros((2, 3)), u]), 2, axis=0) ** 2))
    assert jerk["mcj"] < jerk["mce"]


def test_stl_reactive_waits_for_the_hand_in_the_zone():
    cfg = _cfg(reach_time_s=2.0)
    cfg = cfg.model_copy(update={"stl": cfg.stl.model_copy(update={"zone_radius_m": 1.0})})
    # The hand comes from 2.5 m to 1.5 m from the base at 0.5 m/s: inside the zone only at 1.5 s
    hand = lambda t: np.array([max(1.5, 2.5 - 0.5 * t) + 0.0, 0.0, 0.0]) - np.array([0.6, 0, 0])  # noqa: E731
    run = run_reach(make_controller("stl", cfg), START, hand, 1.0)
    # ||p_h|| = 1.9 .. 1.4 m > l_h = 1.0 m: no trigger, the minimal-|u| robot stays put
    assert np.allclose(run.velocities, 0.0)
    assert run.feasible


def test_stl_predetermined_goes_to_the_handover_location_not_the_hand():
    cfg = _cfg(reach_time_s=2.0)
    cfg = cfg.model_copy(
        update={"stl": cfg.stl.model_copy(update={"strategy": Strategy.PROACTIVE_PREDETERMINED})}
    )
    spot = np.array([0.8, 0.2, 0.1])
    run = run_reach(make_controller("stl", cfg), START, HAND, 2.4, target=spot)
    assert run.feasible
    assert np.abs(run.positions[10] - spot).sum() <= cfg.stl.eps_p_m + 1e-5


def test_observation_rejects_non_finite_points():
    with pytest.raises(ValueError, match="hand"):
        ReachObservation(t=0.0, x=START, hand=np.array([np.nan, 0, 0]))


def test_observation_rejects_a_non_finite_handover_location():
    with pytest.raises(ValueError, match="target"):
        ReachObservation(t=0.0, x=START, hand=HAND, target=np.array([0.5, np.nan, 0.0]))
