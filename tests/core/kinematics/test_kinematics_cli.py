"""``gazebot ik``: the JSON document and the error paths."""

from __future__ import annotations

import argparse
import json
import math

import pytest

from gazebot.apps.cli import ik


def _run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="gazebot")
    sub = parser.add_subparsers(dest="command")
    ik.register(sub)
    args = parser.parse_args(argv)
    return args.func(args)


@pytest.mark.parametrize("robot", ["sawyer", "jaco2"])
def test_ik_json_prints_joints_eyes_and_residuals(robot, capsys):
    assert _run(["ik", "--robot", robot, "--target", "1.1", "0", "1.6", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert set(doc) == {"joints", "eyes", "residual_deg", "total_residual_deg"}
    assert set(doc["eyes"]) == {"yaw", "pitch"}
    assert all(math.isfinite(v) for v in doc["joints"].values())
    assert doc["total_residual_deg"] < 0.5
    if robot == "sawyer":  # pan only: the head cannot look up at the face, the eyes do
        assert set(doc["joints"]) == {"head_pan"}
        assert doc["residual_deg"] > 5 and doc["eyes"]["pitch"] < 0
    else:
        assert set(doc["joints"]) == {"head_pan", "neck_tilt", "head_tilt", "head_roll"}
        assert doc["residual_deg"] < 0.5


def test_ik_text_output_names_joints_in_degrees(capsys):
    assert _run(["ik", "--robot", "jaco2", "--target", "1.0", "0.4", "1.18"]) == 0
    out = capsys.readouterr().out
    assert "head_pan" in out and "deg" in out


def test_ik_rejects_non_finite_targets_and_unknown_robots():
    with pytest.raises(ValueError, match="finite"):
        _run(["ik", "--target", "nan", "0", "1"])
    with pytest.raises(FileNotFoundError, match="unknown robot"):
        _run(["ik", "--robot", "r2d2", "--target", "1", "0", "1"])
