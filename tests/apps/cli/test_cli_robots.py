"""``gazebot robots check`` and ``gazebot demo --robot FILE.yaml`` on a robot described by its
own URDF (the eye-joint head of tests/core/kinematics/eyehead.py): what the engine will use,
one-line errors, exit status, and the demo against a kinematic head."""

from __future__ import annotations

from gazebot.apps.cli import main
from tests.core.kinematics.eyehead import write_robot


def test_model_file_errors_name_the_yaml_and_field(tmp_path, capsys):
    path = write_robot(tmp_path, urdf_ref="package://no_such_pkg/urdf/eyehead.urdf")
    assert main(["robots", "check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and str(path) in err and "'urdf'" in err and "no_such_pkg" in err
    both = tmp_path / "both.yaml"
    both.write_text(path.read_text() + "mjcf: x.xml\n")
    assert main(["robots", "check", str(both)]) == 2
    assert "exactly one model file" in capsys.readouterr().err


def test_robots_check_prints_the_chain_limits_and_reach(tmp_path, capsys):
    path = write_robot(tmp_path)
    assert main(["robots", "check", str(path), "--radius", "1.0"]) == 0
    out = capsys.readouterr().out
    assert "head chain (base to gaze): head_pan -> head_tilt" in out
    assert "[  -85.94,    85.94] deg    171.89 deg/s (model)" in out
    assert "eyes: joints left_eye_pan, right_eye_pan, eye_tilt" in out
    assert "head and eyes" in out and "worst miss" in out


def test_robots_check_fails_on_a_head_joint_that_does_not_turn_the_gaze(tmp_path, capsys):
    path = write_robot(tmp_path)
    path.write_text(path.read_text().replace(
        "gaze_frame: {link: head, xyz: [0.09, 0.0, 0.05]}",
        "gaze_frame: {link: neck, xyz: [0.09, 0.0, 0.05]}"))
    assert main(["robots", "check", str(path), "--radius", "1.0"]) == 1
    assert "head joint 'head_tilt' does not turn the gaze frame" in capsys.readouterr().out


def test_demo_runs_a_urdf_robot_against_a_kinematic_head(tmp_path, capsys):
    import csv
    import json

    path = write_robot(tmp_path)
    out = tmp_path / "demo"
    assert main(["demo", "--robot", str(path), "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["phases"] == ["idle", "reach", "transfer", "retreat", "done"]
    assert summary["final_miss_deg"] < 0.5
    rows = list(csv.DictReader((out / "timeline.csv").open()))
    assert {"head_pan_deg", "left_eye_pan_deg", "eye_tilt_deg", "miss_deg"} <= set(rows[0])
    assert {r["target"] for r in rows} == {"face", "hand"}


def test_robots_list_names_the_shipped_robots_and_the_examples(capsys):
    assert main(["robots", "list"]) == 0
    out = capsys.readouterr().out
    assert "sawyer" in out and "mjcf sawyer.xml" in out
    assert "configs/robots/examples/tiago.yaml" in out
    assert "urdf package://example-robot-data/robots/tiago_description/robots/tiago.urdf" in out
