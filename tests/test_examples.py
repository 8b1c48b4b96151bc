"""The examples a newcomer copies from keep working."""

from __future__ import annotations

import importlib.util
import json
import socket
import sys
import threading
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def test_embed_engine_example_looks_at_face_then_hand_then_face(capsys):
    lines = _load("embed_engine").main([])
    looks = [line.split("look at")[1].split()[0] for line in lines if "look at" in line]
    assert looks == ["face", "hand", "face"]
    phases = [
        word for line in lines
        if (word := line.split()[-1]).endswith("_started") and not word.startswith("robot")
    ]
    assert phases == ["reach_started", "transfer_started", "retreat_started"]


@pytest.mark.zenoh
def test_robot_bridge_example_is_driven_by_the_engine_node_over_zenoh(capsys):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    endpoint = f"tcp/127.0.0.1:{port}"
    bridge = _load("robot_bridge")
    result: dict = {}

    def robot():
        result["rc"] = bridge.main(["--namespace", "/example", "--listen", endpoint,
                                    "--duration", "4"])

    thread = threading.Thread(target=robot)
    thread.start()
    from gazebot.cli import main

    rc = main(["run", "--robot", "sawyer", "--behavior", "face-hand-face",
                 "--namespace", "/example",
               "--connect", endpoint, "--duration", "3", "--json"])
    thread.join(timeout=10)
    out = capsys.readouterr().out
    summary = json.loads(out[out.index("{"): out.rindex("}") + 1])
    assert rc == 0 and result["rc"] == 0
    assert summary["frames"] > 100 and summary["commands"] > 100
    applied = int(out.rsplit("applied", 1)[1].split()[0])
    assert applied > 100
