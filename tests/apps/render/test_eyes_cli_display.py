"""``gazebot render eyes`` and reading a robot's head screen from its YAML."""

from __future__ import annotations

import argparse
import json
import math

import cv2
import pytest
import yaml

from gazebot.apps.cli import render_eyes
from gazebot.apps.render import EyeRenderer, robot_display
from gazebot.core.config import ConfigError


def cli(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="gazebot render")
    render_eyes.register(parser.add_subparsers())
    args = parser.parse_args(["eyes", *argv])
    return args.func(args)


def test_cli_writes_the_image_at_the_robot_screen_size(tmp_path, capsys):
    out = tmp_path / "eyes.png"
    assert (
        cli(["--robot", "jaco2", "--yaw", "20", "--pitch", "-5", "--out", str(out), "--json"]) == 0
    )
    summary = json.loads(capsys.readouterr().out)
    assert summary["width"] == 800 and summary["style"] == "jaco2-head"
    img = cv2.imread(str(out))
    assert img.shape == (480, 800, 3)


def test_cli_takes_degrees_and_matches_the_api_in_radians(tmp_path):
    out = tmp_path / "e.png"
    cli(
        [
            "--yaw",
            "15",
            "--pitch",
            "10",
            "--blink",
            "0.3",
            "--distance",
            "0.7",
            "--width",
            "256",
            "--height",
            "150",
            "--out",
            str(out),
        ]
    )
    expected = EyeRenderer.for_robot("sawyer", width=256, height=150).render(
        math.radians(15), math.radians(10), blink=0.3, distance=0.7
    )
    assert (cv2.imread(str(out))[..., ::-1] == expected).all()


@pytest.mark.parametrize(
    "argv,match",
    [
        (["--blink", "2"], "--blink"),
        (["--yaw", "nan"], "--yaw"),
        (["--out", "eyes.gif"], "--out"),
        (["--robot", "r2d2"], "unknown robot"),
        (["--out", "/no/such/dir/eyes.png"], "does not exist"),
    ],
)
def test_cli_bad_arguments_raise_clear_errors(argv, match, tmp_path):
    argv = argv if "--out" in argv else [*argv, "--out", str(tmp_path / "x.png")]
    with pytest.raises((ValueError, FileNotFoundError), match=match):
        cli(argv)


def test_cli_is_registered_under_the_render_group(tmp_path):
    pytest.importorskip(
        "gazebot.apps.cli.render_video", reason="the render group needs render_video.py"
    )
    from gazebot.apps.cli import render

    parser = argparse.ArgumentParser(prog="gazebot")
    render.register(parser.add_subparsers())
    out = tmp_path / "g.png"
    args = parser.parse_args(
        ["render", "eyes", "--width", "64", "--height", "40", "--out", str(out)]
    )
    assert args.func(args) == 0
    assert cv2.imread(str(out)).shape == (40, 64, 3)


def test_known_robots_have_their_screens():
    assert (robot_display("sawyer").width, robot_display("sawyer").height) == (1024, 600)
    assert (robot_display("jaco2").width, robot_display("jaco2").height) == (800, 480)


def _custom_robot_yaml(tmp_path, **display):
    """configs/robots/sawyer.yaml renamed to a robot gazebot has never heard of."""
    from gazebot.core.config import configs_dir

    data = yaml.safe_load((configs_dir() / "robots" / "sawyer.yaml").read_text())
    data["name"] = "myrobot"
    data["display"].update(display)
    path = tmp_path / "myrobot.yaml"
    path.write_text(yaml.safe_dump(data))
    return path, data


def test_custom_robot_yaml_path_gives_its_own_display(tmp_path):
    path, _ = _custom_robot_yaml(tmp_path, width_px=320, height_px=200)
    info = robot_display(path)
    assert (info.robot, info.width, info.height, info.style) == ("myrobot", 320, 200, "sawyer")
    assert info.yaw_range == pytest.approx(math.radians(40))
    assert info.pitch_range == pytest.approx(math.radians(45))
    assert EyeRenderer.for_robot(path).shape == (200, 320, 3)


def test_for_robot_takes_a_parsed_robot_config(tmp_path):
    from gazebot.core.kinematics.robot_config import load_robot_config

    path, _ = _custom_robot_yaml(tmp_path, width_px=320, height_px=200)
    config, _ = load_robot_config(path)
    r = EyeRenderer.for_robot(config)
    assert r.shape == (200, 320, 3) and r.style.name == "sawyer"
    assert r.yaw_range == pytest.approx(math.radians(40))


def test_eye_range_is_the_larger_side_of_an_asymmetric_yaml_range(tmp_path):
    path, data = _custom_robot_yaml(tmp_path)
    data["eyes"]["yaw_range_deg"] = [-20.0, 30.0]
    path.write_text(yaml.safe_dump(data))
    assert robot_display(path).yaw_range == pytest.approx(math.radians(30))


def test_robot_yaml_with_bad_display_values_raises_config_error(tmp_path):
    path, _ = _custom_robot_yaml(tmp_path, width_px=-3)
    with pytest.raises(ConfigError, match=r"display\.width_px"):
        robot_display(path)
    with pytest.raises(FileNotFoundError):
        robot_display(tmp_path / "missing.yaml")
    with pytest.raises(FileNotFoundError, match="unknown robot 'r2d2'"):
        robot_display("r2d2")
