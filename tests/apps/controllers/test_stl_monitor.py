"""STL robustness (seed 4.2.1) and the handover specs (Tables 4.1-4.3) on met and missed runs."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.controllers import load_controllers_config, make_controller
from gazebot.apps.controllers.config import Role
from gazebot.apps.controllers.rollout import run_reach
from gazebot.apps.controllers.stl_logic import (
    Always,
    Eventually,
    Predicate,
    Signal,
    reach_spec,
    retreat_spec,
    transfer_spec,
)


def _signal_from_run(run, dt, holds=False):
    n = len(run.times)
    return Signal(
        dt=dt,
        values={
            "p_r": run.positions,
            "p_h": run.hands,
            "p_o": run.hands,
            "alpha": np.full(n, 1.0 if holds else 0.0),
            "zone_center": np.zeros((n, 3)),
        },
    )


def test_eventually_and_always_robustness_by_hand():
    s = Signal(dt=0.5, values={"v": np.array([-1.0, 0.5, 2.0, -0.5])})
    pos = Predicate("v>0", lambda s: s["v"])
    assert Eventually(pos, 0, 0.5).rho(s).tolist() == [0.5, 2.0, 2.0, -0.5]
    assert Always(pos, 0, 0.5).rho(s).tolist() == [-1.0, 0.5, -0.5, -0.5]
    assert Always(pos).robustness(s) == -1.0
    assert Eventually(pos).robustness(s) == 2.0


@pytest.mark.parametrize("reach_time", [2.0, 3.0])
def test_reach_spec_robustness_positive_on_a_run_that_meets_it(reach_time):
    cfg = load_controllers_config().model_copy(update={"reach_time_s": reach_time})
    run = run_reach(make_controller("stl", cfg), np.zeros(3), np.array([1.5, 0, 0]), reach_time + 1)
    rho = reach_spec(cfg.stl, reach_time).robustness(_signal_from_run(run, cfg.dt_s))
    assert rho > 0


def test_reach_spec_robustness_negative_on_a_run_that_misses_it():
    cfg = load_controllers_config().model_copy(update={"reach_time_s": 1.0})
    run = run_reach(make_controller("stl", cfg), np.zeros(3), np.array([1.5, 0, 0]), 2.0)
    rho = reach_spec(cfg.stl, 1.0).robustness(_signal_from_run(run, cfg.dt_s))
    assert rho < 0
    # a slow PV reach meets a generous spec and misses a tight one (PV has no timing of its own)
    pv = run_reach(make_controller("pv", cfg), np.zeros(3), np.array([0.5, 0, 0]), 4.0)
    sig = _signal_from_run(pv, cfg.dt_s)
    assert reach_spec(cfg.stl, 3.5).robustness(sig) > 0
    assert reach_spec(cfg.stl, 0.6).robustness(sig) < 0


def test_giver_reach_spec_only_triggers_while_the_robot_holds_the_object():
    cfg = load_controllers_config()
    run = run_reach(make_controller("pv", cfg), np.zeros(3), np.array([1.5, 0, 0]), 0.6)
    spec = reach_spec(cfg.stl, 0.4, role=Role.GIVER)
    assert spec.robustness(_signal_from_run(run, cfg.dt_s, holds=False)) > 0  # vacuous
    assert spec.robustness(_signal_from_run(run, cfg.dt_s, holds=True)) < 0


def test_transfer_and_retreat_specs_sign():
    cfg = load_controllers_config().stl
    n, dt = 11, 0.1
    alpha = np.r_[np.zeros(3), np.full(8, 1.0)]  # the robot holds the object from sample 3
    p_r = np.zeros((n, 3))
    p_r[7:] = [0.3, 0.0, 0.0]  # at the drop-off 0.4 s after taking the object
    sig = Signal(
        dt,
        {
            "alpha": alpha,
            "p_r": p_r,
            "p_d": np.tile([0.3, 0, 0], (n, 1)),
            "p_o": np.zeros((n, 3)),
            "p_h": np.zeros((n, 3)),
        },
    )
    assert retreat_spec(cfg, 0.5, Role.RECEIVER).robustness(sig) > 0
    assert retreat_spec(cfg, 0.3, Role.RECEIVER).robustness(sig) < 0
    # giver: the object shared (0.5 load share) from sample 2; gripper open (1) from sample 5
    g = np.r_[np.zeros(5), np.ones(6)]
    sig = Signal(
        dt,
        {
            "alpha": np.r_[np.ones(2), np.full(9, 0.5)],
            "g_r": g,
            "p_o": np.zeros((n, 3)),
            "p_h": np.zeros((n, 3)),
            "p_r": np.zeros((n, 3)),
        },
    )
    assert transfer_spec(cfg, 0.3, Role.GIVER).robustness(sig) > 0
    assert transfer_spec(cfg, 0.2, Role.GIVER).robustness(sig) < 0


def _monitor_rows(n: int, hand: np.ndarray) -> dict[str, list]:
    """A receiving robot at the object (in the gripper's reach) that never closes its gripper."""
    zero = np.zeros(3)
    return {
        "t": [0.1 * k for k in range(n)],
        "p_r": [zero] * n,
        "p_h": [hand] * n,
        "p_o": [zero] * n,
        "alpha": [0.0] * n,
        "g_r": [1.0] * n,
        "p_d": [zero] * n,
        "p_home": [zero] * n,
    }


def test_run_monitor_transfer_binds_only_while_the_human_holds_or_shares_the_object():
    from gazebot.apps.sim.stl_monitor import HandoverMonitor

    cfg = load_controllers_config()
    # Table 4.2: (||p_o - p_r|| < eps and (o_h or o_s)) => <>[0, t_2] grasped. Object on the
    # ground (o_g: released and away from the hand): the transfer spec does not bind.
    dropped = HandoverMonitor(config=cfg, eps=0.05, dt=0.1)
    dropped.rows = _monitor_rows(30, np.array([1.0, 0.0, 0.0]))
    assert dropped.robustness()["transfer"] > 0
    # Object in the human's hand at the gripper and no grasp within t_2: violated.
    held = HandoverMonitor(config=cfg, eps=0.05, dt=0.1)
    held.rows = _monitor_rows(30, np.zeros(3))
    assert held.robustness()["transfer"] < 0


def test_object_states_without_a_force_sensor_follow_table_4_1():
    from gazebot.apps.controllers.stl_logic import object_states

    cfg = load_controllers_config().stl.model_copy(update={"force_sensor": False})
    at, away = np.zeros(3), np.array([0.5, 0.0, 0.0])
    # samples: robot grips it, human grips it, both grip it, nobody (on the ground)
    sig = Signal(
        0.1,
        {
            "p_o": np.zeros((4, 3)),
            "p_r": np.array([at, away, at, away]),
            "p_h": np.array([away, at, at, away]),
            "g_r": np.array([0.0, 1.0, 0.0, 1.0]),
            "g_h": np.array([1.0, 0.0, 0.0, 1.0]),
        },
    )
    states = object_states(cfg, cfg.eps_p_m)
    for k, name in enumerate(("o_r", "o_h", "o_s", "o_g")):
        positive = {n for n, f in states.items() if f.rho(sig)[k] > 0}
        assert positive == {name}, (k, positive)
    # a gripper at the object but open does not hold it
    open_gripper = Signal(0.1, {**sig.values, "g_r": np.ones(4)})
    assert states["o_r"].rho(open_gripper)[0] < 0


# ------------------------------------------------------------ Table 4.2: t4, t5, t6
def _cfg(force_sensor: bool):
    return load_controllers_config().stl.model_copy(update={"force_sensor": force_sensor})


def _pickup_trace(n: int = 16, arrive: int = 6, close: int = 8) -> Signal:
    """A giver robot: the object on the table at P (nobody holds it: o_g), the gripper there at
    sample ``arrive``, closed on it (g_r = g* = 0) from ``close``, holding it (load share 1) from
    the next sample. 0.1 s per sample; the person's hand far away and open."""
    P = np.array([0.5, 0.0, 0.0])
    k = np.arange(n)
    return Signal(
        0.1,
        {
            "p_r": np.outer(np.minimum(k / arrive, 1.0), P),
            "p_o": np.tile(P, (n, 1)),
            "p_h": np.tile([1.0, 1.0, 0.0], (n, 1)),
            "g_r": np.where(k < close, 1.0, 0.0),
            "g_h": np.ones(n),
            "alpha": np.where(k <= close, 0.0, 1.0),
        },
    )


def _dropoff_trace(D, n: int = 16, arrive: int = 5, open_at: int | None = 8) -> Signal:
    """A receiver robot holding the object (g_r = g*, load share 1) carries it from H0 to the
    drop-off D at sample ``arrive`` and opens (g_r = 1, load share 0) at ``open_at`` (None:
    never); the object stays where the gripper left it."""
    H0, D = np.array([0.3, 0.3, 0.3]), np.asarray(D, float)
    k = np.arange(n)
    p_r = H0 + np.outer(np.minimum(k / arrive, 1.0), D - H0)
    opened = np.zeros(n, bool) if open_at is None else k >= open_at
    return Signal(
        0.1,
        {
            "p_r": p_r,
            "p_o": p_r.copy(),
            "p_d": np.tile([0.6, 0.0, 0.2], (n, 1)),
            "p_h": np.tile([1.0, 1.0, 0.0], (n, 1)),
            "g_r": np.where(opened, 1.0, 0.0),
            "g_h": np.ones(n),
            "alpha": np.where(opened, 0.0, 1.0),
        },
    )


@pytest.mark.parametrize("force_sensor", [True, False])
def test_t4_release_at_the_dropoff_robustness_sign(force_sensor):
    from gazebot.apps.controllers.stl_logic import release_spec

    cfg = _cfg(force_sensor)
    at_d = _dropoff_trace([0.6, 0.0, 0.2])  # at the drop-off at 0.5 s, open at 0.8 s
    assert release_spec(cfg, 0.4).robustness(at_d) > 0
    assert release_spec(cfg, 0.2).robustness(at_d) < 0  # opened 0.3 s after arriving
    never = _dropoff_trace([0.6, 0.0, 0.2], open_at=None)
    assert release_spec(cfg, 1.0).robustness(never) < 0
    # carried elsewhere: never at the drop-off with the object, so t_4 does not bind
    elsewhere = _dropoff_trace([0.6, 0.2, 0.2], open_at=None)
    assert release_spec(cfg, 0.2).robustness(elsewhere) > 0


@pytest.mark.parametrize("force_sensor", [True, False])
def test_t5_reach_the_free_object_robustness_sign(force_sensor):
    from gazebot.apps.controllers.stl_logic import pickup_reach_spec

    cfg = _cfg(force_sensor)
    trace = _pickup_trace()  # at the object 0.6 s after the start
    assert pickup_reach_spec(cfg, 0.8).robustness(trace) > 0
    assert pickup_reach_spec(cfg, 0.4).robustness(trace) < 0
    # the same motion with the person holding the object (o_h, not o_g): t_5 does not bind
    held = Signal(
        trace.dt,
        {**trace.values, "p_h": trace["p_o"], "g_h": np.zeros(trace.n), "g_r": np.ones(trace.n)},
    )
    assert pickup_reach_spec(cfg, 0.4).robustness(held) > 0


@pytest.mark.parametrize("force_sensor", [True, False])
def test_t6_grasp_at_the_object_robustness_sign(force_sensor):
    from gazebot.apps.controllers.stl_logic import pickup_grasp_spec

    cfg = _cfg(force_sensor)
    trace = _pickup_trace()  # at the object at 0.6 s, closed at 0.8 s
    assert pickup_grasp_spec(cfg, 0.3).robustness(trace) > 0
    assert pickup_grasp_spec(cfg, 0.1).robustness(trace) < 0
    never = _pickup_trace(close=99)
    never = Signal(never.dt, {**never.values, "alpha": np.zeros(never.n)})
    assert pickup_grasp_spec(cfg, 0.5).robustness(never) < 0


def test_table_4_2_lists_each_roles_specs_in_task_order():
    from gazebot.apps.controllers.stl_logic import table_4_2

    cfg = load_controllers_config()
    assert list(table_4_2(cfg.stl, 3.0, Role.RECEIVER)) == ["t1", "t2", "t3", "t4"]
    assert list(table_4_2(cfg.stl, 3.0, Role.GIVER)) == ["t5", "t6", "t7", "t8", "t9"]
    # a whole giver task: picked up in time, so t_5 and t_6 hold
    giver = table_4_2(cfg.stl.model_copy(update={"pickup_time_s": 0.8}), 3.0, Role.GIVER)
    trace = _pickup_trace()
    assert giver["t5"].robustness(trace) > 0 and giver["t6"].robustness(trace) > 0
