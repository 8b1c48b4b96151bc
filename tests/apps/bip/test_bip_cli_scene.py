"""``gazebot bip``: train, evaluate --json, bad input as one error line; the robot-giver scene
drives the gaze engine through a whole handover with the hands at the object's width."""

from __future__ import annotations

import json

from gazebot.apps.bip.scene import run_scene
from gazebot.apps.cli import main


def test_train_and_evaluate_json(tmp_path, capsys):
    model, test = tmp_path / "model", tmp_path / "test"
    assert main(["bip", "train", "--synthetic", "12", "--seed", "1", "--out", str(model)]) == 0
    assert main(["bip", "demos", "--synthetic", "2", "--seed", "5", "--widths", "0.2", "0.45",
                 "--out", str(test)]) == 0
    capsys.readouterr()
    assert main(["bip", "evaluate", str(model), "--test", str(test), "--json",
                 "--members", "40"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["modes"]) == {"none", "projection", "filter"}
    for v in out["modes"].values():
        assert v["width_error_mean_m"] >= 0.0 and v["position_error_m"] > 0.0


def test_a_missing_model_is_one_error_line(tmp_path, capsys):
    assert main(["bip", "evaluate", str(tmp_path / "nope"), "--test", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gazebot: error: ") and "bip_prior.npz" in err


def test_train_needs_demos_or_synthetic(tmp_path, capsys):
    assert main(["bip", "train", "--out", str(tmp_path / "m")]) == 2
    assert "--synthetic" in capsys.readouterr().err


def test_scene_runs_the_gaze_engine_through_the_handover(prior, off_mean_tests):
    run = run_scene(prior, off_mean_tests[0], "filter")
    phases = [k.phase for k in run.ticks]
    for phase in ("reach", "transfer", "retreat"):
        assert phase in phases
    assert {"face", "hand"} <= {k.target for k in run.ticks}
    assert run.grip_width_error().mean() < 0.01


def test_train_from_a_demos_folder_and_a_bad_csv_is_named(tmp_path, capsys):
    demos = tmp_path / "demos"
    assert main(["bip", "demos", "--synthetic", "3", "--out", str(demos)]) == 0
    assert main(["bip", "train", str(demos), "--out", str(tmp_path / "m")]) == 0
    (demos / "zz_bad.csv").write_text("t,giver_left_x\n0,1\n", encoding="utf-8")
    capsys.readouterr()
    assert main(["bip", "train", str(demos), "--out", str(tmp_path / "m2")]) == 2
    err = capsys.readouterr().err
    assert "zz_bad.csv" in err and "missing column" in err
