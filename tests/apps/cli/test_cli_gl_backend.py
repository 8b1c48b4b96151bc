"""The demo picks MuJoCo's off-screen back end (the first working of EGL and OSMesa) before
anything loads MuJoCo, so a run that loads a model before it renders (``--controller gps``
checks its policy first) still renders without ``MUJOCO_GL`` set; commands that do not render
leave it alone."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

_CODE = textwrap.dedent(
    """
    import os, sys
    from gazebot.apps.cli import main
    rc = main(sys.argv[1:])
    print(rc, "MUJOCO_GL=" + os.environ.get("MUJOCO_GL", ""))
    """
)


def _run(argv: list[str], **env: str) -> str:
    base = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    out = subprocess.run(
        [sys.executable, "-c", _CODE, *argv], env={**base, **env}, capture_output=True,
        text=True, timeout=300,
    )
    return out.stdout.strip().splitlines()[-1]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="probed on Linux only")
def test_the_demo_chooses_a_working_back_end_before_it_loads_mujoco(tmp_path):
    from gazebot.apps.render.gl_check import BACKENDS, probe

    working = [b for b in BACKENDS if probe(b)[0]]
    if not working:
        pytest.skip("neither EGL nor OSMesa renders on this machine")
    # --controller gps without --policy: refused after the back end is chosen, before any
    # simulation
    line = _run(["demo", "--controller", "gps", "--out", str(tmp_path / "d")])
    assert line == f"2 MUJOCO_GL={working[0]}"


def test_a_command_that_does_not_render_leaves_mujoco_gl_alone():
    assert _run(["behaviors", "list"]) == "0 MUJOCO_GL="
    assert _run(["behaviors", "list"], MUJOCO_GL="osmesa") == "0 MUJOCO_GL=osmesa"
