"""`gazebot demo --controller gps --policy DIR`: a policy trained in seconds (the session's tiny
problem) drives the panda robot's joint torques in the handover scene with the gaze engine in
the loop: the gripper approaches the object in the giver's hand, torques stay finite and within
the Panda's bounds, a non-finite policy output holds the posture, the head and eyes are
commanded, and bad arguments are one-line errors."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from gazebot.apps.cli import main
from gazebot.apps.gps import panda
from gazebot.apps.sim.scene_config import SceneConfig, load_scene

pytest.importorskip("jax", reason="gazebot gps needs the optional extra gazebot[gps]")
pytest.importorskip("sklearn", reason="gazebot gps needs the optional extra gazebot[gps]")


def _scene(policy) -> SceneConfig:
    data = load_scene("default").model_dump()
    data["controller"].update(reach_controller="gps", policy=str(policy))
    return SceneConfig.model_validate(data)


def _run(policy, until_s: float = 6.0, broken: bool = False):
    """Record a handover without video; per tick: time, gripper-object and gripper-hand
    distances, the arm's torques, the controller state and the gripper's position."""
    from gazebot.apps.sim.record import record_handover

    log: list[tuple[float, float, float, np.ndarray, str, np.ndarray]] = []
    sims = []

    def on_tick(sim, tick) -> None:
        if not sims:
            sims.append(sim)
            if broken:
                trained = sim.controller.reach.controller.trained
                object.__setattr__(trained.policy, "b2", np.full_like(trained.policy.b2, np.nan))
        g = sim.data.site_xpos[sim._gripper_site]
        obj = sim.data.mocap_pos[sim.scene.object_mocap]
        hand = float(np.linalg.norm(g - sim.giver.hand))
        log.append((sim.t, float(np.linalg.norm(g - obj)), hand,
                    sim.data.ctrl[sim._arm_act].copy(), sim.controller.state.value, g.copy()))
        if sim.t >= until_s:
            raise _Stop

    rec = None
    try:
        rec = record_handover(robot="panda", scene=_scene(policy), progress=False,
                              on_tick=on_tick)
    except _Stop:
        pass
    return rec, log, sims[0]


class _Stop(Exception):
    pass


def test_the_learned_reach_brings_the_gripper_to_the_object_in_the_givers_hand(trained):
    rec, log, sim = _run(trained, until_s=30.0)
    reach = [row for row in log if row[4] in ("reaching", "at_handover")]
    assert reach, "the policy never reached"
    start_obj, start_hand = reach[0][1], reach[0][2]
    end_obj = min(row[1] for row in log)
    assert end_obj <= sim.config.controller.grasp_distance_m  # close enough to grasp
    assert end_obj < 0.25 * start_obj
    assert min(row[2] for row in log) < 0.5 * start_hand  # and so nearer the hand
    torques = np.array([row[3] for row in log])
    assert np.all(np.isfinite(torques))
    assert np.all(np.abs(torques) <= np.array(panda.TAU_MAX_NM) + 1e-9)
    assert np.abs(torques).max() > 1.0  # the policy really drove the arm
    assert sim.controller.reach.fallbacks == 0
    kinds = [e.kind.value for e in rec.robot_events]
    assert kinds[:3] == ["robot_reach_started", "robot_reach_ended", "robot_grasped"]
    # The gaze engine saw the reach and commanded the head and the eyes.
    assert {t.phase for t in rec.ticks} >= {"reach", "transfer"}
    pans = np.array([t.head["head_pan"] for t in rec.ticks])
    tilts = np.array([t.head["head_tilt"] for t in rec.ticks])
    assert np.all(np.isfinite(pans)) and np.ptp(tilts) > np.radians(5)
    assert {"face", "hand"} <= {t.target for t in rec.ticks}


def test_a_non_finite_policy_output_holds_the_posture_and_is_counted(trained):
    _, log, sim = _run(trained, until_s=3.0, broken=True)
    reach = sim.controller.reach
    assert reach.fallbacks > 0 and "not finite" in reach.fallback_reason
    torques = np.array([row[3] for row in log])
    assert np.all(np.isfinite(torques))
    assert np.all(np.abs(torques) <= np.array(panda.TAU_MAX_NM) + 1e-9)
    reaching = [row[5] for row in log if row[4] == "reaching"]
    assert len(reaching) > 10
    assert np.linalg.norm(reaching[-1] - reaching[0]) < 0.01  # held its posture, no reach


def test_gps_without_a_policy_is_a_one_line_error(tmp_path, capsys):
    assert main(["demo", "--robot", "panda", "--controller", "gps", "--out",
                 str(tmp_path)]) == 2
    assert "--controller gps needs --policy DIR" in capsys.readouterr().err


def test_a_directory_without_a_policy_is_named(tmp_path, capsys):
    assert main(["demo", "--robot", "panda", "--controller", "gps", "--policy",
                 str(tmp_path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "meta.json" in err and "gazebot gps train" in err


def test_a_robot_without_the_panda_torque_arm_is_refused(trained, tmp_path, capsys):
    assert main(["demo", "--robot", "sawyer", "--controller", "gps", "--policy", str(trained),
                 "--out", str(tmp_path)]) == 2
    assert "use --robot panda" in capsys.readouterr().err


def test_a_full_state_policy_names_the_fields_the_scene_lacks(trained, tmp_path, capsys):
    full = tmp_path / "full"
    shutil.copytree(trained, full)
    meta = json.loads((full / "meta.json").read_text())
    meta["state"] = "full"
    (full / "meta.json").write_text(json.dumps(meta))
    # a network of the FULL state's size (49 inputs: the tester's joint angles and velocities
    # added), so the load succeeds and the scene's refusal is what is tested
    from gazebot.apps.gps.state import DIMS, StateKind

    with np.load(full / "policy.npz") as z:
        arrays = {k: z[k] for k in z.files}
    extra = DIMS[StateKind.FULL] - arrays["w1"].shape[0]
    arrays["w1"] = np.vstack([arrays["w1"], np.zeros((extra, arrays["w1"].shape[1]))])
    arrays["x_mean"] = np.concatenate([arrays["x_mean"], np.zeros(extra)])
    arrays["x_scale"] = np.concatenate([arrays["x_scale"], np.ones(extra)])
    np.savez(full / "policy.npz", **arrays)
    assert main(["demo", "--robot", "panda", "--controller", "gps", "--policy", str(full),
                 "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "theta_h" in err and err.count("\n") == 1


def test_a_policy_without_the_gps_controller_is_refused(trained, tmp_path, capsys):
    assert main(["demo", "--robot", "panda", "--controller", "pv", "--policy", str(trained),
                 "--out", str(tmp_path)]) == 2
    assert "--policy is the learned controller's" in capsys.readouterr().err


def test_a_policy_trained_on_other_dynamics_is_refused(trained, tmp_path, capsys):
    other = tmp_path / "other"
    shutil.copytree(trained, other)
    meta = json.loads((other / "meta.json").read_text())
    meta["config"]["scene"]["joint_damping"] = [4.0] * 7
    (other / "meta.json").write_text(json.dumps(meta))
    assert main(["demo", "--robot", "panda", "--controller", "gps", "--policy", str(other),
                 "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "scene.joint_damping" in err and err.count("\n") == 1


def test_a_hand_the_tester_cannot_hold_its_cylinder_at_holds_the_posture(trained):
    from gazebot.apps.sim.simulation import HandoverSimulation

    sim = HandoverSimulation("panda", _scene(trained))
    reach = sim.controller.reach
    q = sim.data.qpos[sim._arm_qpos].copy()
    reach.start(0.0, q)
    step = reach.update(0.0, 0.0, np.array([4.0, 0.0, 1.0]))  # 4 m away: beyond the tester
    assert step.torque is None and reach.fallbacks == 1
    assert reach.fallback_reason.startswith("state: tester hand cannot reach")
    np.testing.assert_allclose(step.q, q)
    step = reach.update(0.05, 0.05, sim.data.mocap_pos[sim.scene.object_mocap])
    assert step.torque is not None and np.all(np.isfinite(step.torque))  # back to the policy


@pytest.mark.parametrize(
    ("argv", "robot"),
    [
        (["--controller", "gps", "--policy", "p"], "panda"),  # the arm the policy was trained on
        (["--controller", "gps", "--policy", "p", "--robot", "jaco2"], "jaco2"),  # refused later
        (["--controller", "pv"], "sawyer"),
        ([], "sawyer"),
    ],
)
def test_the_demo_robot_defaults_to_the_panda_only_for_the_learned_reach(argv, robot):
    from gazebot.apps.cli import build_parser
    from gazebot.apps.cli.demo import default_robot

    args = build_parser().parse_args(["demo", *argv])
    assert default_robot(args) == robot
