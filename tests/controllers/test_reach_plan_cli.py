"""``gazebot reach-plan`` and the demo's controller options."""

from __future__ import annotations

import argparse
import json

import pytest

from gazebot.cli import main


def _plan(capsys, *extra):
    rc = main(["reach-plan", "--start", "0", "0", "0", "--hand", "1.5", "0", "0", "--json", *extra])
    return rc, json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("controller", ["mcj", "mce", "stl"])
def test_reach_plan_reports_an_infeasible_one_second_reach_with_exit_zero(capsys, controller):
    rc, out = _plan(
        capsys,
        "--controller",
        controller,
        "--reach-time",
        "1",
        "--dt",
        "0.2",
        "--horizon",
        "15",
        "--u-max",
        "1",
    )
    assert rc == 0
    assert out["feasible"] is False
    assert out["message"] == "I will not be able to reach in the specified time limit"


def test_reach_plan_path_ends_at_the_hand(capsys):
    rc, out = _plan(capsys, "--controller", "stl", "--reach-time", "2", "--duration", "2.4")
    assert rc == 0 and out["feasible"]
    t, x, y, z = next(p for p in out["path"] if p[0] == pytest.approx(2.0))
    assert abs(x - 1.5) + abs(y) + abs(z) < 0.01
    assert out["solve_ms"] > 0 and out["control_period_ms"] == pytest.approx(200)


def test_reach_plan_giver_role_reaches_with_the_object(capsys):
    rc, out = _plan(
        capsys, "--controller", "stl", "--role", "giver", "--reach-time", "2", "--duration", "2.2"
    )
    assert rc == 0 and out["feasible"] and out["reached_at_s"] <= 2.0


def test_reach_plan_rejects_a_stall_longer_than_the_reach(capsys):
    rc = main(
        [
            "reach-plan",
            "--controller",
            "mce",
            "--start",
            "0",
            "0",
            "0",
            "--hand",
            "1",
            "0",
            "0",
            "--reach-time",
            "1",
            "--stall-time",
            "2",
        ]
    )
    assert rc == 2
    assert "stall_time_s" in capsys.readouterr().err


def test_stall_time_is_only_for_mce(capsys):
    rc = main(
        [
            "reach-plan",
            "--controller",
            "mcj",
            "--start",
            "0",
            "0",
            "0",
            "--hand",
            "1",
            "0",
            "0",
            "--stall-time",
            "0.5",
        ]
    )
    assert rc == 2 and "mce" in capsys.readouterr().err


def test_demo_options_override_the_scene_controller():
    from gazebot.cli.demo import scene_with_overrides

    args = argparse.Namespace(
        scene="default", controller="mce", reach_time=2.5, stall_time=0.5, retreat=None
    )
    scene = scene_with_overrides(args)
    assert scene.controller.reach_controller.value == "mce"
    assert scene.controller.reach_time_s == 2.5 and scene.controller.stall_time_s == 0.5
    plain = argparse.Namespace(
        scene="default", controller=None, reach_time=None, stall_time=None, retreat=None
    )
    assert scene_with_overrides(plain) == "default"
    with pytest.raises(ValueError, match="--controller"):  # a reach time needs a timed controller
        scene_with_overrides(
            argparse.Namespace(
                scene="default", controller=None, reach_time=2.0, stall_time=None, retreat=None
            )
        )
