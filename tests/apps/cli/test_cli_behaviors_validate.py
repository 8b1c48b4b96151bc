"""``gazebot behaviors validate``: every check the engine makes, each error as FILE:LINE: FIELD."""

from __future__ import annotations

from pathlib import Path

import pytest

from gazebot.apps.cli import main
from gazebot.core.config import configs_dir

GOOD = "segments:\n  - {phase: reach, at: 0.0, target: face}\n"

# (name, body, the error's expected text after the file name)
BROKEN = [
    (
        "syntax",
        "segments:\n  - {phase: reach, at: 0.0, target: [face\n",
        ":3:1: invalid YAML: expected ',' or ']', but got '<stream end>'",
    ),
    (
        "unknown-key",
        GOOD + "  - {phase: reach, at: 0.3, tagret: hand}\n",
        ":3: segments[1].tagret: unknown key (known: at, phase, target)",
    ),
    (
        "bad-target",
        "description: d\nsegments:\n  - {phase: reach, at: 0.0, target: face}\n"
        "  - {phase: reach, at: 0.5, target: hnad}\n",
        ":4: segments[1].target: 'hnad' is not a target (known: dropoff, face, hand, ",
    ),
    (
        "bad-phase",
        "segments:\n  - {phase: rech, at: 0.0, target: face}\n",
        ":2: segments[0].phase: expected 'reach', 'transfer' or 'retreat', got 'rech'",
    ),
    (
        "negative-duration",
        GOOD + "tracking_lost:\n  hold_s: -0.5\n",
        ":4: tracking_lost.hold_s: expected greater than or equal to 0, got -0.5",
    ),
    (
        "unknown-event",
        GOOD + "  - {phase: retreat, at: {after: retreat_begun, delay: 0.2}, target: face}\n",
        ":3: segments[1].at.after: expected 'reach_started', ",
    ),
    (
        "wrong-type",
        "before: [face]\n" + GOOD,
        ":1: before: expected a valid string, got ['face']",
    ),
]


@pytest.mark.parametrize(("name", "body", "error"), BROKEN, ids=[b[0] for b in BROKEN])
def test_a_broken_behavior_exits_2_naming_file_line_and_field(tmp_path, capsys, name, body, error):
    path = tmp_path / f"{name}.yaml"
    path.write_text(body)
    assert main(["behaviors", "validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert any(line.startswith(f"{path}{error}") for line in err.splitlines()), err


def test_every_error_of_every_file_is_printed(tmp_path, capsys):
    bad = tmp_path / "b1.yaml"
    bad.write_text(
        "segments:\n  - {phase: reach, at: 1.5, target: face}\n"
        "  - {phase: reach, at: $later, target: hnad}\n"
        "  - {phase: transfer, at: {after: robot_grasped, delay: -1}, target: hand}\n"
    )
    good = tmp_path / "good.yaml"
    good.write_text(GOOD)
    missing = tmp_path / "missing.yaml"
    assert main(["behaviors", "validate", str(bad), str(missing), str(good)]) == 2
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert lines[:4] == [
        f"{bad}:2: segments[0].at: expected a fraction of the phase between 0 and 1, got 1.5",
        f"{bad}:3: segments[1].at: expected a defined parameter (known: []), got '$later'",
        f"{bad}:3: segments[1].target: 'hnad' is not a target (known: dropoff, face, hand, "
        "handover_location, object, receiver_hand, rest)",
        f"{bad}:4: segments[2].at.delay: expected greater than or equal to 0, got -1",
    ]
    assert lines[4].startswith(f"{missing}: ") and "not found" in lines[4]
    assert lines[5] == "2 of 3 behavior files have errors"
    assert out == f"{good}: ok\n"


def test_targets_are_checked_against_the_robots_points(tmp_path, capsys):
    path = tmp_path / "shelf.yaml"
    path.write_text(GOOD + "  - {phase: retreat, at: 0.5, target: dropoff}\n")
    assert main(["behaviors", "validate", str(path)]) == 0  # the default robot has `dropoff`
    robot = tmp_path / "bare.yaml"
    text = (configs_dir() / "robots" / "sawyer.yaml").read_text()
    assert "  dropoff:" in text
    robot.write_text(
        "\n".join(line for line in text.splitlines() if not line.startswith("  dropoff:"))
    )
    capsys.readouterr()
    assert main(["behaviors", "validate", "--robot", str(robot), str(path)]) == 2
    assert f"{path}:3: segments[1].target: 'dropoff' is not a target" in capsys.readouterr().err


def test_every_builtin_behavior_and_the_example_are_valid(capsys):
    files = sorted((configs_dir() / "behaviors").glob("*.yaml"))
    example = Path(__file__).parents[3] / "examples" / "look-at-dropoff.yaml"
    assert len(files) >= 9
    assert main(["behaviors", "validate", *map(str, files), str(example)]) == 0
    assert capsys.readouterr().out.count(": ok\n") == len(files) + 1


def test_show_and_demo_report_the_same_error_before_any_simulation(tmp_path, capsys):
    path = tmp_path / "b1.yaml"
    path.write_text(BROKEN[2][1])
    expected = f"gazebot: error: {path}{BROKEN[2][2]}"
    assert main(["behaviors", "show", str(path)]) == 2
    assert capsys.readouterr().err.startswith(expected)
    out = tmp_path / "demo"
    assert main(["demo", "--behavior", str(path), "--out", str(out), "--no-progress"]) == 2
    assert capsys.readouterr().err.startswith(expected)
    assert not (out / "handover.mp4").exists()
