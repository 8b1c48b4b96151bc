"""The seed's Table 4.4 (section 4.4.3): the reach-phase rule that splits giving motions, and the
STL controller's success rate over them per reach time and speed cap."""

from __future__ import annotations

import json

import numpy as np
import pytest

from gazebot.apps.controllers.config import ControllersConfig
from gazebot.apps.controllers.giving_motions import (
    SEED_D1,
    SEED_V1,
    motion_from_path,
    seed_reach_phase,
)
from gazebot.apps.controllers.reach_table import SEED_TABLE_4_4, table_4_4, table_config
from gazebot.apps.sim.giving_motions import simulated_motions


def test_seed_reach_phase_starts_past_d1_of_the_way_and_ends_below_v1_of_the_peak_speed():
    # A 1 s straight reach of 0.5 m, min-jerk, after 0.5 s at rest, then 0.5 s held.
    t = np.arange(0.0, 2.0 + 1e-9, 0.01)
    tau = np.clip((t - 0.5) / 1.0, 0, 1)
    s = tau**3 * (10 - 15 * tau + 6 * tau**2)
    hand = np.column_stack([0.5 * s, np.zeros_like(t), np.zeros_like(t)])
    start, end = seed_reach_phase(t, hand)
    # By hand: distance 0.5 s(tau) first exceeds 0.41 * 0.5 where s(tau) > 0.41; the speed
    # (distance's rate, positive away from the start) 0.5 * 30 tau^2 (1 - tau)^2 first drops
    # below 0.43 of its peak 0.5 * 1.875 after that.
    dist = 0.5 * s
    speed = np.gradient(dist, t)
    exp_start = int(np.flatnonzero(dist > SEED_D1 * 0.5)[0])
    exp_end = exp_start + 1 + int(np.flatnonzero(speed[exp_start + 1 :] < SEED_V1 * speed.max())[0])
    assert (start, end) == (exp_start, exp_end)
    assert 0.4 < tau[start] < 0.5  # s(0.45) = 0.43 > 0.41 > s(0.44)
    assert 0.78 < tau[end] < 0.81  # 16 tau^2 (1 - tau)^2 = 0.43 at tau = 0.793


def test_a_reach_still_speeding_at_the_recordings_end_has_no_valid_phase():
    t = np.linspace(0.0, 1.0, 50)
    hand = np.column_stack([t**2, np.zeros_like(t), np.zeros_like(t)])  # accelerating away
    assert seed_reach_phase(t, hand) is None
    assert motion_from_path("accelerating", t, hand, np.zeros(3)) is None


def test_table_config_uses_the_seeds_remaining_parameters():
    cfg = table_config(ControllersConfig(), 0.5, 4.0)
    assert (cfg.u_max_m_s, cfg.reach_time_s, cfg.dt_s) == (0.5, 4.0, 0.2)
    assert (cfg.stl.horizon, cfg.stl.eps_p_m) == (20, 0.01)


@pytest.fixture(scope="module")
def small_table():
    motions = simulated_motions(10, seed=0)
    assert len(motions) == 10
    rows = table_4_4(motions, ControllersConfig())
    return {(r.u_max_m_s, r.reach_time_s): r.percent for r in rows}


def test_success_rate_rises_with_the_reach_time_at_both_caps(small_table):
    for cap, times in ((1.0, (1.0, 2.0, 3.0)), (0.5, (2.0, 3.0, 4.0))):
        rates = [small_table[(cap, t1)] for t1 in times]
        assert rates == sorted(rates), (cap, rates)
        assert rates[-1] > rates[0], (cap, rates)


def test_success_rate_falls_with_the_lower_speed_cap(small_table):
    for t1 in (2.0, 3.0):
        assert small_table[(0.5, t1)] < small_table[(1.0, t1)], t1
    assert set(small_table) == set(SEED_TABLE_4_4)


def test_reach_table_cli_prints_each_cell_beside_the_seeds(capsys):
    from gazebot.apps.cli import main

    assert main(["reach-table", "--motions", "2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["motions"] == 2
    assert [(r["u_max_m_s"], r["t1_s"]) for r in out["rows"]] == list(SEED_TABLE_4_4)
    assert [r["seed_percent"] for r in out["rows"]] == list(SEED_TABLE_4_4.values())
    assert all(0 <= r["percent"] <= 100 for r in out["rows"])


def test_reach_table_cli_names_a_missing_recording(capsys):
    from gazebot.apps.cli import main

    assert main(["reach-table", "--motions", "0", "--recording", "/no/such/folder"]) == 2
    assert "/no/such/folder" in capsys.readouterr().err


def _pose_folder(path, rate=120.0):
    """A KTH-like pose folder: the giver's right hand reaches 0.6 m toward the taker in 1 s
    (minimum jerk) after 0.5 s at rest; the taker's hand and shoulder stand still."""
    path.mkdir()
    t = np.arange(0.0, 2.5, 1.0 / rate)
    tau = np.clip(t - 0.5, 0, 1)
    s = tau**3 * (10 - 15 * tau + 6 * tau**2)
    bodies = {
        "giver_RHand": np.column_stack([1.2 - 0.6 * s, 0 * t, 1.0 + 0 * t]),
        "taker_RHand": np.tile([0.3, 0.1, 1.0], (len(t), 1)),
        "taker_RShoulder": np.tile([0.0, 0.2, 1.4], (len(t), 1)),
    }
    for name, xyz in bodies.items():
        rows = "\n".join(",".join(f"{v:.6f}" for v in (*p, 1, 0, 0, 0)) for p in xyz)
        (path / f"{name}_pose_saved.csv").write_text("x,y,z,q0,q1,q2,q3\n" + rows + "\n")
    return path


def test_a_recording_gives_a_motion_in_the_receivers_frame(tmp_path):
    from gazebot.apps.controllers.giving_motions import motion_from_recording

    m = motion_from_recording(_pose_folder(tmp_path / "rec"), "giver_RHand", "taker_RHand",
                              "taker_RShoulder", rate=120.0)
    assert m is not None
    assert np.allclose(m.robot_start, [0.3, -0.1, -0.4])  # the taker's hand from its shoulder
    assert np.allclose(m.hand[0], [1.2, -0.2, -0.4])
    assert np.allclose(np.diff(m.t), 1 / 7)  # the seed's 7 Hz
    assert 0.5 < m.t[m.reach_start] < m.t[m.reach_end] < 1.5


def test_reach_table_cli_adds_recordings(tmp_path, capsys):
    from gazebot.apps.cli import main

    rec = _pose_folder(tmp_path / "rec")
    assert main(["reach-table", "--motions", "0", "--recording", str(rec), "--rate", "120",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["motions"] == 1 and out["recordings"] == [str(rec)]
