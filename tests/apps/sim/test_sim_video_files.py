"""Video files: a custom robot YAML works end to end (demo and ``render video``) because every part
reads the same parsed robot config; a run that fails leaves no (partial, invalid) MP4 behind; the
shared H.264 writer; and the one-way dependency render <- sim."""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import subprocess
import sys

import imageio
import numpy as np
import pytest
import yaml

from gazebot.apps.cli import demo, render_video
from gazebot.apps.render.video import open_h264_writer
from gazebot.apps.sim.record import render_handover_video
from gazebot.core.config import configs_dir


def _custom_robot(tmp_path, **changes):
    """configs/robots/sawyer.yaml copied to tmp_path under a name gazebot has never heard of."""
    data = yaml.safe_load((configs_dir() / "robots" / "sawyer.yaml").read_text())
    data["name"] = "myrobot"
    data.update(changes)
    path = tmp_path / "myrobot.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _cli(module, argv):
    parser = argparse.ArgumentParser()
    module.register(parser.add_subparsers())
    args = parser.parse_args(argv)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = args.func(args)
    return code, out.getvalue()


def _frames(path):
    with imageio.get_reader(path, format="FFMPEG") as reader:
        return [f for f in reader]


@pytest.mark.slow
def test_demo_with_a_custom_robot_yaml_writes_a_decodable_video(tmp_path):
    robot = _custom_robot(tmp_path)
    out = tmp_path / "demo"
    argv = ["demo", "--robot", str(robot), "--out", str(out), "--no-progress", "--json"]
    code, stdout = _cli(demo, [*argv, "--width", "96", "--height", "64"])
    assert code == 0
    summary = json.loads(stdout)
    assert summary["completed"] and summary["frames"] > 30
    frames = _frames(out / "handover.mp4")
    assert len(frames) == summary["frames"] and frames[0].shape == (64, 96, 3)


@pytest.mark.slow
def test_render_video_with_a_custom_robot_yaml(tmp_path):
    robot = _custom_robot(tmp_path)
    out = tmp_path / "v.mp4"
    argv = ["video", "--robot", str(robot), "--behavior", "hand", "--out", str(out)]
    code, _ = _cli(render_video, [*argv, "--width", "64", "--height", "48", "--no-progress"])
    assert code == 0 and len(_frames(out)) > 30


def test_failing_render_leaves_no_video_file(tmp_path):
    # The YAML parses, but its eye style does not exist: the run fails at the first frame, after
    # the video was opened.
    robot = _custom_robot(tmp_path, eye_style="no-such-style")
    out = tmp_path / "videos" / "handover.mp4"
    with pytest.raises(FileNotFoundError, match="no-such-style"):
        render_handover_video(robot, "hand", "default", out, width=64, height=48, progress=False)
    assert not out.exists()
    assert list(out.parent.iterdir()) == []


def test_failing_run_keeps_an_earlier_good_video(tmp_path):
    out = tmp_path / "clip.mp4"
    frame = np.full((32, 48, 3), 90, np.uint8)
    with open_h264_writer(out, 10, (48, 32)) as writer:
        writer.append(frame)
    good = out.read_bytes()
    with pytest.raises(RuntimeError), open_h264_writer(out, 10, (48, 32)) as writer:
        writer.append(frame)
        raise RuntimeError("crash mid-video")
    assert out.read_bytes() == good
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clip.mp4"]


def test_h264_writer_writes_yuv420p_h264_deterministically(tmp_path):
    rng = np.random.default_rng(0)
    frames = rng.integers(0, 255, (5, 32, 48, 3), dtype=np.uint8)
    paths = []
    for name in ("a.mp4", "b.mp4"):
        with open_h264_writer(tmp_path / name, 10, (48, 32)) as writer:
            for f in frames:
                writer.append(f)
        paths.append(tmp_path / name)
    assert paths[0].read_bytes() == paths[1].read_bytes()
    with imageio.get_reader(paths[0], format="FFMPEG") as reader:
        meta = reader.get_meta_data()
        assert meta["codec"] == "h264" and meta["pix_fmt"].startswith("yuv420p")
        assert len([f for f in reader]) == 5


def test_h264_writer_rejects_bad_sizes_frames_and_empty_videos(tmp_path):
    with pytest.raises(ValueError, match="even"):
        open_h264_writer(tmp_path / "x.mp4", 10, (47, 32))
    with pytest.raises(ValueError, match="fps"):
        open_h264_writer(tmp_path / "x.mp4", 0, (48, 32))
    with pytest.raises(ValueError, match=r"\(32, 48, 3\) uint8"):
        with open_h264_writer(tmp_path / "x.mp4", 10, (48, 32)) as writer:
            writer.append(np.zeros((48, 32, 3), np.uint8))
    with pytest.raises(ValueError, match="no frames"):
        with open_h264_writer(tmp_path / "x.mp4", 10, (48, 32)):
            pass
    assert list(tmp_path.iterdir()) == []


def test_render_package_does_not_import_the_simulation_or_the_engine():
    code = (
        "import sys, gazebot.apps.render, gazebot.apps.render.video, gazebot.apps.render.timeline;"
        "print(sorted(m for m in sys.modules"
        " if m.startswith(('gazebot.apps.sim', 'gazebot.core.engine', 'mujoco'))))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
