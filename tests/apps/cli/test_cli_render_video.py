"""``gazebot render video --help`` says where the observer camera is (issue 32)."""

from __future__ import annotations

import pytest

from gazebot.apps.cli import main


def test_render_video_help_puts_the_camera_in_front_of_the_robot(capsys):
    with pytest.raises(SystemExit) as done:
        main(["render", "video", "--help"])
    assert done.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "in front of the robot" in text and "at the side" not in text
