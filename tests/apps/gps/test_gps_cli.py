"""`gazebot gps train` and `gazebot gps evaluate` end to end on a tiny problem (0.5 s trials, three
iterations, a coarse grid): the learning makes progress and the evaluation reports the seed's
numbers in the documented JSON shape."""

from __future__ import annotations

import json

import pytest
import yaml

from gazebot.apps.cli import main

pytest.importorskip("jax", reason="gazebot gps needs the optional extra gazebot[gps]")
pytest.importorskip("sklearn", reason="gazebot gps needs the optional extra gazebot[gps]")


def test_training_lowers_the_local_controllers_cost_and_saves_the_policy(trained):
    meta = json.loads((trained / "meta.json").read_text())
    costs = [e["local_cost"] for e in meta["log"]]
    assert len(costs) == 4
    assert costs[-1] < costs[0]
    errors = [e["local_error_m"] for e in meta["log"]]
    assert errors[-1] < errors[0]
    assert meta["controllers"] == 8 and meta["state"] == "reduced"
    assert (trained / "policy.npz").is_file()


def test_evaluate_prints_the_documented_summary(trained, capsys):
    capsys.readouterr()
    assert main(["gps", "evaluate", str(trained), "--tester", "moving", "--grid", "2",
                 "--json", "--quiet"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert set(summary) >= {"train_error_m", "test_error_mean_m", "test_error_std_m",
                            "test_error_max_m", "n"}
    assert summary["n"] == 3 * 2 * 2
    assert 0 <= summary["test_error_mean_m"] <= summary["test_error_max_m"]


def test_evaluate_names_a_directory_that_is_not_a_policy(tmp_path, capsys):
    assert main(["gps", "evaluate", str(tmp_path), "--json"]) == 2
    err = capsys.readouterr().err
    assert "meta.json" in err and "gazebot gps train" in err


def test_evaluate_rejects_a_non_positive_mass(trained, capsys):
    with pytest.raises(SystemExit):
        main(["gps", "evaluate", str(trained), "--mass", "-1"])
    assert "expected a finite number > 0" in capsys.readouterr().err


def test_demo_renders_one_frame_per_control_step(trained, tmp_path, capsys):
    from gazebot.apps.render.gl_check import ensure_gl_backend

    try:
        ensure_gl_backend()
    except Exception as exc:  # no EGL/OSMesa on this machine
        pytest.skip(f"no off-screen GL: {exc}")
    capsys.readouterr()
    video = tmp_path / "reach.mp4"
    assert main(["gps", "demo", str(trained), "--out", str(video), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert video.stat().st_size > 0
    assert summary["frames"] == 1 + 20  # 1 s trials at 20 Hz in the tiny configuration
    assert summary["error_m"] >= 0


def test_train_names_a_shell_the_tester_cannot_reach(tiny_config, tmp_path, capsys):
    data = yaml.safe_load(tiny_config.read_text(encoding="utf-8"))
    data["scene"]["tester"]["forearm_m"] = 0.1  # reach 0.6 m: the shell is beyond it
    bad = tmp_path / "gps.yaml"
    bad.write_text(yaml.safe_dump(data), encoding="utf-8")
    assert main(["gps", "train", "--config", str(bad), "--out", str(tmp_path / "p"),
                 "--quiet"]) == 2
    assert "out of the tester's reach" in capsys.readouterr().err
