"""A recorded giver replayed in the simulator: retargeted to the scene's rest and handover
location, timed by the recording with the robot's grasp in the loop."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.apps.cli import main
from gazebot.apps.sim.giver import GiverPlan, GiverState
from gazebot.apps.sim.giver_replay import RecordedHandover, ReplayedGiver, load_giver_motion
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.io.recordings import RecordingError

REST = np.array([0.85, -0.1, 1.0])
OFFER = np.array([0.55, -0.05, 1.1])


@pytest.fixture(scope="module")
def recorded():
    sh = generate(12, SyntheticOptions(rate=120.0, noise=0.001, marker_offset=0.4))
    return sh, RecordedHandover.from_trajectory(sh.trajectory)


def _run(giver, grasp_at, t_end=12.0, dt=1 / 120):
    out = []
    for t in np.arange(0.0, t_end, dt):
        giver.update(t, t >= grasp_at)
        out.append((t, giver.state, giver.hand.copy(), giver.hand_velocity(t)))
    return out


def test_replayed_hand_goes_from_rest_to_the_handover_location_and_back(recorded):
    _, rec = recorded
    plan = GiverPlan(start_t=0.5, reach_s=1.0, transfer_s=0.5, retreat_s=1.0)
    giver = ReplayedGiver(rec, REST, OFFER, plan)
    grasp_at = 0.5 + (rec.transfer_start - rec.reach_start) + 0.4  # the robot is late
    states = _run(giver, grasp_at)
    first = states[0]
    assert np.allclose(first[2], REST) and first[1] is GiverState.IDLE
    offer = [s for s in states if s[1] is GiverState.OFFER]
    assert offer and all(np.allclose(s[2], OFFER) for s in offer)  # waits for the grasp
    assert offer[-1][0] < grasp_at <= offer[-1][0] + 1 / 60
    assert giver.state is GiverState.DONE
    assert np.linalg.norm(giver.hand - REST) < 0.02
    assert all(np.isfinite(s[3]).all() for s in states)
    # The recorded transfer's length is kept.
    share = [s[0] for s in states if s[1] is GiverState.SHARE]
    assert share[-1] - share[0] == pytest.approx(rec.transfer_end - rec.transfer_start, abs=0.02)


def test_reach_keeps_the_recorded_timing(recorded):
    _, rec = recorded
    plan = GiverPlan(start_t=1.0, reach_s=9.0, transfer_s=9.0, retreat_s=9.0)
    giver = ReplayedGiver(rec, REST, OFFER, plan)
    states = _run(giver, grasp_at=0.0, t_end=8.0)
    reach = [s[0] for s in states if s[1] is GiverState.REACH]
    assert reach[0] == pytest.approx(1.0, abs=0.01)
    assert reach[-1] - reach[0] == pytest.approx(rec.transfer_start - rec.reach_start, abs=0.02)


def test_recording_without_a_handover_is_an_input_error(tmp_path):
    from gazebot.core.phases import Trajectory

    t = np.arange(0, 3, 0.01)
    still = Trajectory(t, np.tile([1.0, 0, 1], (t.size, 1)), np.tile([0.3, 0, 1], (t.size, 1)))
    path = still.to_csv(tmp_path / "still.csv")
    with pytest.raises(RecordingError, match="still.csv: needs a whole handover"):
        load_giver_motion(str(path))


def test_demo_with_a_wrong_giver_name_fails_with_exit_2(recorded, tmp_path, capsys):
    sh, _ = recorded
    path = sh.trajectory.to_csv(tmp_path / "giver.csv")
    argv = ["demo", "--giver-motion", str(path), "--giver-hand", "wrist", "--out", str(tmp_path)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"gazebot: error: {path}: no point named 'wrist'") and "giver_hand" in err


def test_a_scene_with_giver_motion_replays_it(recorded, tmp_path):
    # Study scenes are scene YAMLs: the same key drives them.
    from gazebot.apps.sim.giver_replay import ReplayedGiver
    from gazebot.apps.sim.scene_config import GiverMotionConfig, SceneConfig
    from gazebot.apps.sim.simulation import HandoverSimulation

    sh, _ = recorded
    path = sh.trajectory.to_csv(tmp_path / "giver.csv")
    scene = SceneConfig(name="replay", giver_motion=GiverMotionConfig(file=str(path)))
    with HandoverSimulation("sawyer", scene) as sim:
        assert isinstance(sim.giver, ReplayedGiver)
        assert np.allclose(sim.tracking().giver_hand, sim.layout.rest_hand, atol=0.01)
