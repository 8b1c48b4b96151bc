"""The scene composes for every robot and scene config, with the parts the video needs."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from gazebot.apps.sim.robot import load_sim_robot
from gazebot.apps.sim.scene import OBSERVER, build_scene
from gazebot.apps.sim.scene_config import Posture, load_scene, scene_names
from gazebot.core.config import ConfigError

ROBOTS = ("sawyer", "jaco2")
SCENES = (
    "default",
    "sitting",
    "standing",
    "large-object",
    "small-object",
    "fragile",
    "non-fragile",
)


def test_shipped_scenes_cover_the_seed_conditions():
    assert set(SCENES) <= set(scene_names())


@pytest.mark.parametrize("robot", ROBOTS)
@pytest.mark.parametrize("scene", SCENES)
def test_scene_builds_with_robot_giver_object_camera_and_display(robot, scene):
    cfg = load_scene(scene)
    built = build_scene(load_sim_robot(robot), cfg)
    m = built.model
    assert m.camera(OBSERVER).id >= 0
    assert m.texture("display").id >= 0 and m.site("gaze").id >= 0
    for body in ("giver", "giver_upper_arm", "giver_forearm", "giver_hand", "handover_object"):
        assert m.body(body).id >= 0
    has_table = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "scene_table") >= 0
    assert has_table == (cfg.posture is Posture.SITTING)
    lay = built.layout
    # The giver offers the object where the robot's gripper will be, and stands on its far side.
    np.testing.assert_allclose(lay.offer_hand + lay.object_offset, lay.handover_location)
    assert lay.shoulder[0] > lay.offer_hand[0] > lay.handover_location[0]
    reach = np.linalg.norm(lay.offer_hand - lay.shoulder)
    assert reach < built.giver.dims.arm_length
    assert built.giver.face_point[2] > lay.handover_location[2]


def test_sitting_giver_is_lower_and_rests_the_object_on_the_table():
    robot = load_sim_robot("sawyer")
    standing = build_scene(robot, load_scene("default"))
    sitting = build_scene(robot, load_scene("sitting"))
    assert sitting.giver.face_point[2] < standing.giver.face_point[2] - 0.3
    lay = sitting.layout
    bottom = lay.rest_hand[2] + lay.object_offset[2] - sitting.obj.half_height
    assert lay.table_top is not None and bottom == pytest.approx(lay.table_top, abs=0.01)


def test_objects_differ_by_condition():
    robot = load_sim_robot("sawyer")
    small = build_scene(robot, load_scene("small-object")).obj
    large = build_scene(robot, load_scene("large-object")).obj
    assert large.half_height > 2 * small.half_height
    glass = build_scene(robot, load_scene("fragile")).obj
    plastic = build_scene(robot, load_scene("non-fragile")).obj
    assert glass.rgba != plastic.rgba


def test_unknown_scene_names_the_known_ones():
    with pytest.raises(FileNotFoundError, match="default"):
        load_scene("no-such-scene")


def test_malformed_scene_yaml_names_file_and_field(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("posture: lying\n")
    with pytest.raises(ConfigError) as err:
        load_scene(bad)
    assert err.value.field == "posture" and "bad.yaml" in str(err.value)
    bad.write_text("giver:\n  reach: {mean_s: 3.0, sd_s: 0.1, min_s: 0.5, max_s: 2.0}\n")
    with pytest.raises(ConfigError, match="giver.reach"):
        load_scene(bad)


def test_unknown_robot_is_a_clear_error():
    with pytest.raises(FileNotFoundError, match="unknown robot"):
        load_sim_robot("r2d2")
