"""``gazebot render eyes`` and reading a robot's head screen from its YAML."""

from __future__ import annotations

import argparse
import json
import math

import cv2
import pytest

from gazebot.cli import render_eyes
from gazebot.config import ConfigError
from gazebot.render import EyeRenderer, robot_display


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
    pytest.importorskip("gazebot.cli.render_video", reason="the render group needs render_video.py")
    from gazebot.cli import render

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


@pytest.mark.parametrize(
    "text",
    [
        "name: bot\ndisplay:\n  width_px: 320\n  height_px: 200\n  eye_style: cartoon\n"
        "eyes:\n  yaw_range_deg: [-20, 20]\n  pitch_range_deg: 15\n",
        "name: bot\ndisplay_resolution: [320, 200]\neye_style: cartoon\n"
        "eye_yaw_range_deg: 20\neye_pitch_range_deg: [-15, 10]\n",
        "name: bot\nscreen:\n  resolution_px: [320, 200]\neyes:\n  style: cartoon\n"
        "eye_limits_deg:\n  yaw: [-20, 20]\n  pitch: [-15, 15]\n",
    ],
)
def test_robot_yaml_layouts_are_read_tolerantly(tmp_path, text):
    path = tmp_path / "bot.yaml"
    path.write_text(text)
    info = robot_display(path)
    assert (info.width, info.height, info.style) == (320, 200, "cartoon")
    assert info.yaw_range == pytest.approx(math.radians(20))
    assert info.pitch_range == pytest.approx(math.radians(15))
    r = EyeRenderer.for_robot(path)
    assert r.shape == (200, 320, 3) and r.style.name == "cartoon"


def test_robot_yaml_without_display_falls_back_to_the_builtin_table(tmp_path):
    path = tmp_path / "sawyer.yaml"
    path.write_text("name: sawyer\nhead_joints: [head_pan]\n")
    info = robot_display(path)
    assert (info.width, info.height, info.style) == (1024, 600, "sawyer")


def test_robot_yaml_with_bad_display_values_raises_config_error(tmp_path):
    path = tmp_path / "bot.yaml"
    path.write_text("name: bot\ndisplay:\n  width_px: -3\n  height_px: 200\n")
    with pytest.raises(ConfigError, match="display_width_px"):
        robot_display(path)
    path.write_text("name: bot\ndisplay:\n  width_px: 30\n  height_px: 20\neye_yaw_range_deg: 95\n")
    with pytest.raises(ConfigError, match="eye_yaw_range_deg"):
        robot_display(path)
    with pytest.raises(FileNotFoundError):
        robot_display(tmp_path / "missing.yaml")
