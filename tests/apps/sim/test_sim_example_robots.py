"""Robots gazebot has never seen, from the URDFs example-robot-data ships (Baxter, TIAGo, PR2,
iCub, Romeo), each described only by a short robot YAML: ``gazebot robots check`` passes, and
the engine, fed a synthetic handover, points the gaze within 0.5 deg of every target the head's
joint limits allow (the eyes on Baxter's screen covering the rest), every head command within
the model's position and velocity limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.apps.cli import main
from gazebot.apps.sim.kinematic_head import run_kinematic_head, synthetic_handover
from gazebot.core.config import configs_dir
from gazebot.core.kinematics import RobotModel, solve_ik
from gazebot.core.kinematics.model_files import package_search_path, resolve_package_uri
from gazebot.core.kinematics.reach import ON_TARGET

EXAMPLES = configs_dir() / "robots" / "examples"
ROBOTS = ["baxter", "tiago", "pr2", "icub", "romeo"]

pytestmark = pytest.mark.skipif(
    resolve_package_uri("package://example-robot-data/package.xml", package_search_path())
    is None,
    reason="example-robot-data is not installed (pip install 'example-robot-data>=6,<7')",
)


@pytest.mark.parametrize("name", ROBOTS)
def test_the_robot_yaml_is_short_and_takes_its_urdf_from_the_package(name):
    text = (EXAMPLES / f"{name}.yaml").read_text()
    assert len(text.splitlines()) <= 15
    assert "urdf: package://example-robot-data/" in text
    assert "mjcf" not in text


@pytest.mark.parametrize("name", ROBOTS)
def test_robots_check_passes(name, capsys):
    assert main(["robots", "check", str(EXAMPLES / f"{name}.yaml")]) == 0
    assert "ok: the engine can use this robot" in capsys.readouterr().out


@pytest.mark.parametrize("name", ROBOTS)
def test_the_engine_looks_at_every_target_the_head_can_reach_within_its_limits(name):
    robot = RobotModel.load(EXAMPLES / f"{name}.yaml")
    frames = synthetic_handover(robot)
    ticks = run_kinematic_head(robot, frames)
    dt = frames[1].t - frames[0].t
    previous = None
    settled: dict[str, int] = {}
    reachable = {}
    for k, tick in enumerate(ticks):
        q = robot.head_vector(tick.head)
        np.testing.assert_array_equal(q, [tick.head[n] for n in robot.head_joints])  # in limits
        if previous is not None:
            speed = np.abs(q - previous) / dt
            assert np.all(speed <= robot.velocity_limits * (1 + 1e-9) + 1e-9), tick.t
        previous = q
        assert robot.eye_yaw_range[0] <= tick.eye_yaw <= robot.eye_yaw_range[1]
        assert robot.eye_pitch_range[0] <= tick.eye_pitch <= robot.eye_pitch_range[1]
        # A target that has stayed put for a second: the gaze has settled on it.
        back = k - int(round(1.0 / dt))
        if back < 0 or any(
            t.target != tick.target or not np.array_equal(t.target_point, tick.target_point)
            for t in ticks[back:k]
        ):
            continue
        key = tuple(tick.target_point)
        if key not in reachable:
            reachable[key] = solve_ik(robot, tick.target_point).total_residual
        # Where the head and eyes can look, within 0.5 deg; elsewhere no worse than the best.
        assert tick.miss <= max(reachable[key], 0.0) + ON_TARGET, (tick.t, tick.target)
        settled[tick.target] = settled.get(tick.target, 0) + 1
    assert settled.get("face", 0) > 30 and settled.get("hand", 0) > 10, settled
    assert all(v <= ON_TARGET for v in reachable.values()), "the handover points are in view"


def test_baxter_eyes_take_what_its_pan_only_head_cannot(capsys):
    robot = RobotModel.load(EXAMPLES / "baxter.yaml")
    ticks = run_kinematic_head(robot, synthetic_handover(robot))
    pitches = [abs(t.eye_pitch) for t in ticks if t.target == "hand"]
    assert max(pitches) > math.radians(10.0)  # the handover location is well below the screen
    assert min(t.miss for t in ticks if t.target == "hand") < math.radians(0.5)
