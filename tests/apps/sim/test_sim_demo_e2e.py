"""End to end: ``gazebot demo`` runs a simulated handover with the gaze engine in the loop and
writes a decodable H.264 video, the per-tick timeline CSV and the timeline plot."""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import json
import math

import imageio
import mujoco
import numpy as np
import pytest

from gazebot.apps.cli import demo
from gazebot.apps.sim.record import record_handover, render_handover_video
from gazebot.apps.sim.robot import load_sim_robot

pytestmark = pytest.mark.slow


def _collapse(values):
    out = []
    for v in values:
        if not out or out[-1] != v:
            out.append(v)
    return out


def _run_cli(argv):
    parser = argparse.ArgumentParser()
    demo.register(parser.add_subparsers())
    args = parser.parse_args(["demo", *argv])
    return args.func(args)


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        code = _run_cli(["--out", str(out), "--seed", "0", "--no-progress", "--json"])
    with (out / "timeline.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    return code, out, rows, json.loads(stdout.getvalue())


def test_demo_writes_video_timeline_and_plot(demo_run):
    code, out, rows, _ = demo_run
    assert code == 0
    for name in ("handover.mp4", "timeline.csv", "timeline.png"):
        assert (out / name).stat().st_size > 1000
    assert imageio.v3.imread(out / "timeline.png").shape[2] in (3, 4)
    assert {"t", "phase", "target", "head_pan", "eye_yaw", "eye_pitch"} <= set(rows[0])


def test_video_decodes_with_one_frame_per_30th_of_a_second(demo_run):
    _, out, rows, _ = demo_run
    t_end = float(rows[-1]["t"])
    expected = math.floor(t_end * 30 + 1e-6) + 1
    reader = imageio.get_reader(out / "handover.mp4")
    meta = reader.get_meta_data()
    frames = [f for f in reader]
    reader.close()
    assert meta["codec"] == "h264" and meta["pix_fmt"].startswith("yuv420p")
    assert meta["fps"] == 30.0
    assert len(frames) == expected
    assert frames[0].shape == (480, 640, 3)
    # Ticks at 120 Hz: four ticks per frame.
    assert len(rows) == pytest.approx(4 * expected, abs=4)


def test_phases_go_reach_transfer_retreat(demo_run):
    _, _, rows, _ = demo_run
    phases = [
        p for p in _collapse(r["phase"] for r in rows) if p in ("reach", "transfer", "retreat")
    ]
    assert phases == ["reach", "transfer", "retreat"]


def test_face_hand_face_target_sequence(demo_run):
    _, _, rows, _ = demo_run
    assert _collapse(r["target"] for r in rows) == ["face", "hand", "face"]


def _line_of_sight_azimuth(model, data, site, joint, angle):
    data.qpos[model.joint(joint).qposadr[0]] = angle
    mujoco.mj_kinematics(model, data)
    x_axis = data.site(site).xmat.reshape(3, 3)[:, 0]
    return math.atan2(x_axis[1], x_axis[0]), data.site(site).xpos.copy()


def _azimuth_error(row, model, data, target):
    az, origin = _line_of_sight_azimuth(
        model, data, "gaze", "head_pan", float(row["head_pan_measured"])
    )
    p = np.array([float(row[f"{target}_{a}"]) for a in "xyz"])
    want = math.atan2(p[1] - origin[1], p[0] - origin[0])
    return abs(math.degrees(az - want))


def test_head_turns_toward_the_hand_then_back_to_the_face(demo_run):
    _, _, rows, _ = demo_run
    robot = load_sim_robot("sawyer")
    model = mujoco.MjModel.from_xml_path(str(robot.mjcf))
    data = mujoco.MjData(model)
    targets = [r["target"] for r in rows]
    to_hand = targets.index("hand")
    to_face = to_hand + targets[to_hand:].index("face")
    t = np.array([float(r["t"]) for r in rows])
    settle = lambda i: int(np.searchsorted(t, t[i] + 0.9))  # noqa: E731
    before = _azimuth_error(rows[to_hand - 1], model, data, "hand")
    after = _azimuth_error(rows[settle(to_hand)], model, data, "hand")
    assert after < 2.0 and before > after + 5.0
    before_face = _azimuth_error(rows[to_face - 1], model, data, "face")
    after_face = _azimuth_error(rows[settle(to_face)], model, data, "face")
    assert after_face < 2.0 and before_face > after_face + 5.0


def test_jaco2_head_points_its_line_of_sight_at_the_hand():
    rec = record_handover("jaco2", "face-hand-face", "default", out_path=None, progress=False)
    assert rec.completed
    assert [p for p in _collapse(k.phase for k in rec.ticks) if p not in ("idle", "done")] == [
        "reach",
        "transfer",
        "retreat",
    ]
    robot = load_sim_robot("jaco2")
    model = mujoco.MjModel.from_xml_path(str(robot.mjcf))
    data = mujoco.MjData(model)

    def angle_to(tick, point):
        for j, q in tick.head_measured.items():
            data.qpos[model.joint(j).qposadr[0]] = q
        mujoco.mj_kinematics(model, data)
        site = data.site(robot.gaze_site)
        d = point - site.xpos
        return math.degrees(math.acos(site.xmat.reshape(3, 3)[:, 0] @ d / np.linalg.norm(d)))

    i = next(k for k, tick in enumerate(rec.ticks) if tick.target == "hand")
    j = next(k for k, tick in enumerate(rec.ticks) if tick.t >= rec.ticks[i].t + 0.9)
    before, after = (
        angle_to(rec.ticks[i - 1], rec.ticks[i - 1].hand),
        angle_to(rec.ticks[j], rec.ticks[j].hand),
    )
    assert after < before - 10.0


def test_video_is_deterministic_for_a_seed(tmp_path):
    a = render_handover_video(
        "sawyer",
        "hand",
        "default",
        tmp_path / "a.mp4",
        seed=3,
        width=160,
        height=120,
        progress=False,
    )
    b = render_handover_video(
        "sawyer",
        "hand",
        "default",
        tmp_path / "b.mp4",
        seed=3,
        width=160,
        height=120,
        progress=False,
    )
    assert a.read_bytes() == b.read_bytes()


def test_bad_video_size_is_a_clear_error(tmp_path):
    with pytest.raises(ValueError, match="even"):
        render_handover_video("sawyer", "hand", "default", tmp_path / "x.mp4", width=641)


def test_demo_json_summary_lists_robot_events(demo_run):
    *_, summary = demo_run
    assert summary["completed"] and summary["frames"] > 0
    kinds = [e["kind"] for e in summary["robot_events"]]
    assert kinds == [
        "robot_reach_started",
        "robot_reach_ended",
        "robot_grasped",
        "robot_retreat_started",
        "robot_retreat_ended",
    ]
    assert summary["robot_events"][0]["planned_duration"] > 0
