"""``gazebot reach-plan`` and the demo's controller options."""

from __future__ import annotations

import argparse
import json

import pytest

from gazebot.apps.cli import main


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
    from gazebot.apps.cli.demo import scene_with_overrides

    args = argparse.Namespace(
        scene="default", controller="mce", reach_time=2.5, stall_time=0.5, retreat=None
    )
    scene = scene_with_overrides(args)
    assert scene.controller.reach_controller == "mce"
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


@pytest.mark.parametrize(
    "extra,names",
    [
        (["--controller", "stl", "--strategy", "proactive-predetermined"], "--target"),
        (["--controller", "stl", "--target", "nan", "0", "0"], "--target"),
        (["--controller", "mcj", "--hand-velocity", "0", "inf", "0"], "--hand-velocity"),
        (["--controller", "mcj", "--stall-time", "0.5"], "--stall-time"),
        (["--controller", "pv", "--duration", "1e9"], "--duration"),
    ],
)
def test_reach_plan_bad_input_is_a_usage_error_naming_the_option(capsys, extra, names):
    rc = main(["reach-plan", "--start", "0", "0", "0", "--hand", "1", "0", "0", *extra])
    assert rc == 2
    assert names in capsys.readouterr().err


def test_reach_plan_reports_arrival_at_a_predetermined_location(capsys):
    rc, out = _plan(
        capsys,
        "--controller",
        "stl",
        "--strategy",
        "proactive-predetermined",
        "--target",
        "0.8",
        "0",
        "0",
        "--reach-time",
        "2",
    )
    assert rc == 0 and out["feasible"] and out["goal"] == "target"
    assert out["reached_at_s"] is not None and out["reached_at_s"] <= 2.0 + 1e-9
    assert out["final_gap_m"] <= 0.01


@pytest.mark.parametrize(
    "options,message",
    [
        ({"controller": "mcj", "stall_time": 0.5}, "mce controller"),
        ({"controller": "mce", "reach_time": 1.0, "stall_time": 2.0}, "stall_time_s"),
        ({"controller": "mce", "stall_time": 3.5}, "stall_time_s"),  # the YAML's 3 s reach
    ],
)
def test_demo_rejects_a_stall_without_mce_or_not_shorter_than_the_reach(options, message):
    from gazebot.apps.cli.demo import scene_with_overrides
    from gazebot.apps.cli.errors import UsageError

    args = argparse.Namespace(
        scene="default", controller=None, reach_time=None, stall_time=None, retreat=None
    )
    vars(args).update(options)
    with pytest.raises(UsageError, match=message):
        scene_with_overrides(args)


@pytest.mark.parametrize(
    "argv,message",
    [
        (["reach-plan", "--controller", "mcj", "--reach-time", "-2"], "--reach-time: expected"),
        (["reach-plan", "--controller", "mcj", "--horizon", "0"], "--horizon: expected"),
        (["reach-plan", "--controller", "mcj", "--dt", "0"], "--dt: expected"),
    ],
)
def test_reach_plan_out_of_range_option_names_it_without_pydantics_report(capsys, argv, message):
    rc = main([*argv, "--start", "0", "0", "0", "--hand", "1", "0", "0"])
    err = capsys.readouterr().err
    assert rc == 2 and err.startswith(f"gazebot: error: {message}")
    assert "errors.pydantic.dev" not in err and len(err.strip().splitlines()) == 1


def test_demo_out_of_range_reach_time_names_the_option():
    from gazebot.apps.cli.demo import scene_with_overrides
    from gazebot.apps.cli.errors import UsageError

    args = argparse.Namespace(
        scene="default", controller="mcj", reach_time=-1.0, stall_time=None, retreat=None
    )
    with pytest.raises(UsageError, match=r"^--reach-time: expected greater than 0, got -1.0$"):
        scene_with_overrides(args)


@pytest.mark.parametrize(
    "controller,reach_time,arrival",
    [("mcj", "3", "; reached at 2.8 s,"), ("stl", "1", "; not reached,")],
)
def test_reach_plan_text_prints_a_rounded_arrival_or_not_reached(
    capsys, controller, reach_time, arrival
):
    """Fig. 4.4's setting: MCJ arrives at 2.8 s (not 2.8000000000000003), STL in 1 s never."""
    argv = ["reach-plan", "--controller", controller, "--reach-time", reach_time]
    rc = main([*argv, "--start", "0", "0", "0", "--hand", "1.5", "0", "0", "--horizon", "15"])
    out = capsys.readouterr().out
    assert rc == 0 and arrival in out and "None" not in out
