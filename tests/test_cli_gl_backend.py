"""Every command picks MuJoCo's off-screen back end before anything imports MuJoCo, so a
command that loads a model before it renders (``demo --controller gps`` checks its policy
first) still renders without ``MUJOCO_GL`` set."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="EGL is chosen on Linux only")
def test_a_command_chooses_egl_before_mujoco_loads_when_mujoco_gl_is_unset():
    code = textwrap.dedent(
        """
        import os, sys
        from gazebot.cli import main
        main(["behaviors", "list"])
        print("MUJOCO_GL=" + os.environ.get("MUJOCO_GL", ""), "mujoco" in sys.modules)
        """
    )
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "MUJOCO_GL=egl False"


def test_mujoco_gl_set_by_the_user_is_kept():
    code = "import os; from gazebot.cli import main; main(['behaviors', 'list']); " \
        "print(os.environ['MUJOCO_GL'])"
    env = dict(os.environ, MUJOCO_GL="osmesa")
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "osmesa"
