"""The core install (``pip install gazebot``, no extras) embeds the engine and puts it on the bus:
gazebot.core and gazebot.io import nothing of an extra, the command line starts, ``gazebot run``
runs, and the example that embeds the engine works."""

from __future__ import annotations

import pytest

from tests.blocked_extras import REPO, gazebot_without_extras, run_without_extras


def test_every_core_and_io_module_imports_without_an_extra():
    res = run_without_extras(
        "import pkgutil, importlib, gazebot.core, gazebot.io\n"
        "names = [m.name for p in (gazebot.core, gazebot.io)\n"
        "         for m in pkgutil.walk_packages(p.__path__, p.__name__ + '.')]\n"
        "for name in names:\n"
        "    importlib.import_module(name)\n"
        "import gazebot\n"
        "assert gazebot.GazeEngine.__module__ == 'gazebot.core.engine'\n"
        "print(len(names))\n"
    )
    assert res.returncode == 0, res.stderr
    # Every module was imported: one per file but the two layers' own __init__.py.
    files = [f for layer in ("core", "io") for f in (REPO / "gazebot" / layer).rglob("*.py")]
    assert int(res.stdout) == len(files) - 2


def test_the_command_line_and_its_help_start_without_an_extra():
    res = gazebot_without_extras("run", "--help")
    assert res.returncode == 0, res.stderr
    assert "--duration" in res.stdout


@pytest.mark.zenoh
def test_gazebot_run_without_the_render_extra_runs_with_eye_state_only():
    import socket

    with socket.socket() as s:  # a port nothing listens on: no other bus is joined
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    res = gazebot_without_extras("run", "--duration", "0.5", "--json", "--listen",
                                 "tcp/127.0.0.1:0", "--connect", f"tcp/127.0.0.1:{port}")
    assert res.returncode == 0, res.stderr
    assert "no eye frames (they need the [render] extra)" in res.stderr
    assert '"robot_seen": false' in res.stdout


def test_the_embedding_example_runs_without_an_extra():
    res = run_without_extras(
        "import runpy, sys\n"
        "sys.argv = ['embed_engine.py']\n"
        f"runpy.run_path({str(REPO / 'examples' / 'embed_engine.py')!r}, run_name='__main__')\n"
    )
    assert res.returncode == 0, res.stderr
    assert "look at hand" in res.stdout


def test_the_wheels_copy_of_the_interface_package_names_its_types_as_the_repositorys(tmp_path):
    import shutil

    from gazebot.io.ros2.typestore import msgs_package_dir, read_msg_files

    wheel_copy = tmp_path / "_gazebot_msgs"  # where pyproject.toml's force-include puts it
    shutil.copytree(msgs_package_dir() / "msg", wheel_copy / "msg")
    assert read_msg_files(wheel_copy) == read_msg_files(msgs_package_dir())
    assert "gazebot_msgs/msg/HandoverEvent" in read_msg_files(wheel_copy)
