"""The STL controller beyond the reach: Table 4.2's giver pick-up (t_5 to the object, t_6 grasp),
the receiver's carry to the drop-off (t_3) and release there (t_4), each synthesized and checked
against the specification's own robustness (``stl_logic``)."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.controllers import ReachObservation, load_controllers_config, make_controller
from gazebot.apps.controllers.config import Role
from gazebot.apps.controllers.stl_gripper import STLGripper
from gazebot.apps.controllers.stl_logic import (
    Signal,
    pickup_grasp_spec,
    pickup_reach_spec,
    release_spec,
    retreat_spec,
)

OBJECT = np.array([0.35, -0.3, 0.95])
DROPOFF = np.array([0.3, -0.35, 0.85])
HAND = np.array([0.9, 0.1, 1.0])


def _cfg(role: Role, **stl):
    cfg = load_controllers_config()
    return cfg.model_copy(update={"stl": cfg.stl.model_copy(update={"role": role, **stl})})


def _closed_loop(ctrl, x0, steps, **obs):
    """Apply each plan's first velocity for one period; returns positions and plans."""
    x, xs, plans = np.asarray(x0, float), [np.asarray(x0, float)], []
    for k in range(steps):
        plan = ctrl.plan(ReachObservation(t=k * ctrl.dt, x=x, hand=HAND, **obs))
        plans.append(plan)
        x = x + plan.command * ctrl.dt
        xs.append(x)
    return np.array(xs), plans


def test_a_giver_with_the_object_on_the_ground_goes_to_it_within_t5():
    cfg = _cfg(Role.GIVER, pickup_time_s=1.6)
    ctrl = make_controller("stl", cfg)
    xs, plans = _closed_loop(ctrl, [0.0, 0.3, 1.2], 10, object_free=True, object_position=OBJECT)
    assert ctrl.active.name == "t5" and all(p.feasible for p in plans)
    n = len(xs)
    sig = Signal(
        ctrl.dt,
        {
            "p_r": xs,
            "p_o": np.tile(OBJECT, (n, 1)),
            "p_h": np.tile(HAND, (n, 1)),
            "alpha": np.zeros(n),  # on the ground: nobody holds it
        },
    )
    assert pickup_reach_spec(cfg.stl, 1.6).robustness(sig) > 0
    # 0.6 m along y at 1 m/s per axis: no run gets there within 0.4 s
    assert pickup_reach_spec(cfg.stl, 0.4).robustness(sig) < 0
    # once it holds the object, the giver's reach (Table 4.3, t_7) takes over
    ctrl.plan(ReachObservation(t=2.0, x=xs[-1], hand=HAND, robot_holds_object=True))
    assert ctrl.active.name == "t7"


def test_a_pickup_too_far_for_t5_stops_the_robot():
    ctrl = make_controller("stl", _cfg(Role.GIVER, pickup_time_s=0.4))
    plan = ctrl.plan(
        ReachObservation(
            t=0.0, x=[0.0, 0.3, 1.2], hand=HAND, object_free=True, object_position=OBJECT
        )
    )
    assert not plan.feasible and np.all(plan.velocities == 0)


def test_a_receiver_holding_the_object_carries_it_to_the_dropoff_within_t3():
    cfg = _cfg(Role.RECEIVER, retreat_time_s=1.4)
    ctrl = make_controller("stl", cfg)
    start = np.array([0.55, 0.0, 1.0])
    xs, plans = _closed_loop(ctrl, start, 9, robot_holds_object=True, dropoff=DROPOFF)
    assert ctrl.active.name == "t3" and all(p.feasible for p in plans)
    n = len(xs)
    sig = Signal(
        ctrl.dt,
        {
            "p_r": xs,
            "p_d": np.tile(DROPOFF, (n, 1)),
            "p_o": xs,
            "p_h": np.tile(HAND, (n, 1)),
            "alpha": np.ones(n),
        },
    )
    assert retreat_spec(cfg.stl, 1.4, Role.RECEIVER).robustness(sig) > 0


def _gripper_run(gripper, g0, goal, within_s, steps):
    g, gs = g0, [g0]
    for k in range(steps):
        plan = gripper.plan(k * gripper.dt, g, goal, True, within_s)
        g = float(np.clip(g + plan.command * gripper.dt, 0, 1))
        gs.append(g)
    return np.array(gs), plan


def test_the_gripper_grasps_within_t6_and_opens_within_t4():
    cfg = load_controllers_config()
    gripper = STLGripper(cfg.stl, cfg.dt_s)
    closed, _ = _gripper_run(gripper, 1.0, cfg.stl.grip_width, 0.6, 6)
    n = len(closed)
    at_object = Signal(
        cfg.dt_s,
        {
            "p_r": np.tile(OBJECT, (n, 1)),
            "p_o": np.tile(OBJECT, (n, 1)),
            "p_h": np.tile(HAND, (n, 1)),
            "g_r": closed,
            "alpha": np.zeros(n),  # the load share only comes once it lifts (after this run)
        },
    )
    assert pickup_grasp_spec(cfg.stl, 0.6).robustness(at_object) > 0
    gripper.reset()
    opened, _ = _gripper_run(gripper, cfg.stl.grip_width, 1.0, 0.4, 6)
    at_dropoff = Signal(
        cfg.dt_s,
        {
            "p_r": np.tile(DROPOFF, (n, 1)),
            "p_d": np.tile(DROPOFF, (n, 1)),
            "p_o": np.tile(DROPOFF, (n, 1)),
            "p_h": np.tile(HAND, (n, 1)),
            "g_r": opened,
            "alpha": np.where(opened > 0.5, 0.0, 1.0),  # holds it until it opens
        },
    )
    assert release_spec(cfg.stl, 0.4).robustness(at_dropoff) > 0


def test_a_grasp_faster_than_the_gripper_can_close_stops_it():
    cfg = load_controllers_config()  # 4 openness/s: 1 -> within 0.1 of 0 takes 0.225 s
    gripper = STLGripper(cfg.stl, cfg.dt_s)
    plan = gripper.plan(0.0, 1.0, cfg.stl.grip_width, True, 0.2)
    assert not plan.feasible and plan.command == 0.0
    assert gripper.plan(0.0, 1.0, cfg.stl.grip_width, True, 0.4).feasible


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_the_gripper_rejects_a_non_finite_openness(bad):
    cfg = load_controllers_config()
    with pytest.raises(ValueError, match="finite"):
        STLGripper(cfg.stl, cfg.dt_s).plan(0.0, bad, 0.0, True, 1.0)
