"""Table 4.2's whole task in the simulator with the STL controller: the receiving robot reaches,
grasps, carries the object to its drop-off and lets go there (t_1-t_4); the giving robot picks
the object up first (t_5, t_6), then hands it over (t_7-t_9). Each run's STL monitor must show
every specification met; a release deadline the gripper cannot meet is reported violated."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from gazebot.apps.sim.scene_config import SceneConfig, load_scene
from gazebot.core.config import ConfigError
from gazebot.core.types import EventKind

pytest.importorskip("mujoco")


def _run(scene, until: float = 12.0):
    from gazebot.apps.sim.simulation import HandoverSimulation
    from gazebot.apps.sim.stl_monitor import HandoverMonitor

    sim = HandoverSimulation(robot="jaco2", scene=scene, seed=0)
    monitor, events, states = HandoverMonitor(), [], []
    start_object = sim.data.mocap_pos[sim.scene.object_mocap].copy()
    while sim.t < until and not sim.done:
        sim.step(1 / 30)
        monitor.sample(sim)
        events += sim.robot_events()
        if not states or states[-1][1] != sim.controller.state.value:
            states.append((sim.t, sim.controller.state.value))
    return sim, monitor.robustness(), events, states, start_object


@pytest.fixture(scope="module")
def receiver():
    return _run("stl-receiver-whole-task")


@pytest.fixture(scope="module")
def giver():
    return _run("stl-giver-whole-task")


def test_the_receiver_meets_t1_to_t4_and_leaves_the_object_at_the_dropoff(receiver):
    sim, rho, events, states, _ = receiver
    assert sim.done
    assert set(rho) == {"reach", "transfer", "retreat", "release"}
    assert all(v > 0 for v in rho.values()), rho
    kinds = [e.kind for e in events]
    order = [
        EventKind.ROBOT_GRASPED,
        EventKind.ROBOT_RETREAT_STARTED,
        EventKind.ROBOT_RELEASED,
        EventKind.ROBOT_RETREAT_ENDED,
    ]
    assert [kinds.index(k) for k in order] == sorted(kinds.index(k) for k in order)
    assert [s for _, s in states][-4:] == ["carrying", "dropping", "retreating", "done"]
    # the object stays where the gripper let go of it, within the grasp distance + its offset
    dropoff = np.array(sim.config.controller.dropoff_m)
    obj = sim.data.mocap_pos[sim.scene.object_mocap]
    assert np.linalg.norm(obj - dropoff) < 0.1
    gripper = sim.data.site_xpos[sim._gripper_site]
    assert np.linalg.norm(gripper - dropoff) > 0.2  # the robot went home without it


def test_the_giver_picks_the_object_up_first_and_meets_t5_to_t9(giver):
    sim, rho, events, states, start_object = giver
    assert sim.done
    assert set(rho) == {"reach", "transfer", "retreat", "pickup", "pickup_grasp"}
    assert all(v > 0 for v in rho.values()), rho
    assert np.allclose(start_object, sim.config.controller.pickup_m)  # on the pick-up spot
    names = [s for _, s in states]
    assert names[:2] == ["picking_up", "pick_grasping"]
    grasped_at = next(t for t, s in states if s not in ("picking_up", "pick_grasping"))
    reach_start = next(e.t for e in events if e.kind is EventKind.ROBOT_REACH_STARTED)
    assert reach_start >= grasped_at  # the handover starts once the robot holds the object
    # the object ends in the person's hand
    obj = sim.data.mocap_pos[sim.scene.object_mocap]
    assert np.linalg.norm(obj - (sim.giver.hand + sim.layout.object_offset)) < 0.06


def test_a_release_deadline_the_gripper_cannot_meet_is_violated_and_it_stops(tmp_path: Path):
    from gazebot.apps.controllers.config import default_controllers_path

    doc = yaml.safe_load(default_controllers_path().read_text())
    doc["stl"]["release_time_s"] = 0.2  # 4 openness/s: opening takes 0.2 s + the margin
    controllers = tmp_path / "controllers.yaml"
    controllers.write_text(yaml.safe_dump(doc))
    data = load_scene("stl-receiver-whole-task").model_dump()
    data["controller"]["controllers"] = str(controllers)
    sim, rho, _, states, _ = _run(SceneConfig.model_validate(data), until=9.0)
    assert rho["release"] < 0 and rho["reach"] > 0 and rho["retreat"] > 0
    assert sim.controller.gripper_infeasible_at is not None
    assert states[-1][1] == "dropping" and not sim.controller.dropped  # stopped, still holding


@pytest.mark.parametrize(
    ("update", "message"),
    [
        (
            {
                "direction": "human-to-robot",
                "controller": {"pickup_m": [0.3, 0, 1], "reach_controller": "stl"},
            },
            "pickup_m needs direction: robot-to-human",
        ),
        (
            {"controller": {"dropoff_m": [0.3, 0, 1], "reach_controller": "mce"}},
            "dropoff_m needs reach_controller: stl",
        ),
    ],
)
def test_a_whole_task_scene_needs_stl_and_the_matching_direction(tmp_path, update, message):
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump({"name": "x", **update}))
    with pytest.raises(ConfigError, match=message):
        load_scene(path)
