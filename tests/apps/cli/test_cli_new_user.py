"""What a new user trips on, README in hand: a second ``gazebot sim`` on a taken port, the
offline-only seed rules run online, help texts."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from gazebot.apps.cli import build_parser, main

REPO = Path(__file__).resolve().parents[3]
SAMPLE = REPO / "examples" / "sample-handover.csv"


@pytest.mark.zenoh
def test_sim_on_a_taken_port_is_a_one_line_error_not_a_traceback():
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        env = {**os.environ, "PYTHONPATH": str(REPO), "MUJOCO_GL": os.environ["MUJOCO_GL"]}
        res = subprocess.run(
            [sys.executable, "-m", "gazebot", "sim", "--robot", "sawyer", "--headless",
             "--duration", "1", "--listen", f"tcp/127.0.0.1:{port}"],
            capture_output=True, text=True, env=env, timeout=300,
        )
    assert res.returncode == 2
    assert res.stderr.count("\n") == 1, res.stderr
    assert res.stderr.startswith(f"gazebot: error: cannot listen on tcp/127.0.0.1:{port}: ")
    assert "already in use" in res.stderr and "Traceback" not in res.stderr


def test_bus_failure_finds_zenohs_error_in_any_wrapping():
    import zenoh  # a required dependency: its absence is a failure, not a skip

    from gazebot.apps.cli.bus import bus_failure

    inner = zenoh.ZError(
        "Can not create a new TCP listener bound to tcp/127.0.0.1:7447: [127.0.0.1:7447: "
        "Address already in use (os error 98) at /x/tcp.rs:61.] at /x/unicast.rs:338."
    )
    try:
        try:
            raise inner
        except zenoh.ZError as exc:
            raise RuntimeError("the driver's own words") from exc
    except RuntimeError as wrapped:
        msg = bus_failure(wrapped)
    assert msg is not None and msg.startswith("cannot listen on tcp/127.0.0.1:7447:")
    assert ".rs" not in msg
    assert bus_failure(ValueError("not the bus")) is None


@pytest.mark.parametrize("method", ["seed-4.4.3", "seed-7.2.5"])
def test_offline_seed_rules_run_online_say_so_on_stderr(method, capsys):
    assert main(["phases", str(SAMPLE), "--method", method, "--online"]) == 0
    err = capsys.readouterr().err
    assert f"--method {method}" in err and "meant offline on a recording of one handover" in err
    assert main(["phases", str(SAMPLE), "--method", method]) == 0
    assert capsys.readouterr().err == ""  # offline, as meant: no warning
    assert main(["phases", str(SAMPLE), "--online"]) == 0
    assert capsys.readouterr().err == ""


def _parsers(parser=None, path=("gazebot",)):
    import argparse

    parser = parser or build_parser()
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _parsers(sub, (*path, name))


def test_help_texts_show_no_raw_rest_markup():
    for path, parser in _parsers():
        assert "``" not in parser.format_help(), " ".join(path)


def test_every_option_of_every_command_says_what_it_does():
    import argparse

    missing = [
        f"{' '.join(path)} {a.option_strings or a.dest}"
        for path, parser in _parsers()
        for a in parser._actions
        if a.help is None and not isinstance(a, (argparse._HelpAction, argparse._SubParsersAction))
    ]
    assert missing == []


def test_study_render_help_describes_its_options(capsys):
    with pytest.raises(SystemExit):
        main(["study", "render", "--help"])
    out = capsys.readouterr().out
    for words in ("plan CSV written by", "study folder to write", "video width, px",
                  "frames per second", "no progress bar"):
        assert words in out
