"""``gazebot view`` without the Foxglove SDK: one line saying what to install, exit 2."""

from __future__ import annotations

import sys

from gazebot.apps import cli


def test_view_without_the_foxglove_sdk_says_what_to_install(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "foxglove", None)  # import foxglove -> ImportError
    assert cli.main(["view", "--connect", "tcp/127.0.0.1:1", "--duration", "0.1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == ("gazebot: error: gazebot view needs the [view] extra (the Foxglove SDK): "
                   "pip install 'gazebot[view]'")


def test_view_is_a_command_with_a_port():
    args = cli.build_parser().parse_args(["view", "--port", "9000"])
    assert args.port == 9000 and args.host == "127.0.0.1"
