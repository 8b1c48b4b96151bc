"""The examples a newcomer copies from keep working."""

from __future__ import annotations

import importlib
import importlib.util
import json
import socket
import sys
import threading
import time
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
def test_robot_bridge_example_is_driven_by_the_engine_node_over_zenoh(capsys, monkeypatch):
    from gazebot.apps.cli import main
    from gazebot.io.drivers.engine_node import EngineNode

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    endpoint = f"tcp/127.0.0.1:{port}"
    bridge = _load("robot_bridge")
    result: dict = {}
    # Both run for a time of the wall clock: the bridge (4 s) starts once the engine has
    # loaded and claimed the robot, and the engine's 3 s count from its first joint state,
    # so they overlap for nearly all of them however slowly either starts.
    engine_started = threading.Event()
    start = EngineNode.start

    def start_then_wait_for_the_robot(node):
        replayed = start(node)
        engine_started.set()
        deadline = time.monotonic() + 60
        while node.driver.joint_state() is None and time.monotonic() < deadline:
            time.sleep(0.005)
        return replayed

    monkeypatch.setattr(EngineNode, "start", start_then_wait_for_the_robot)

    def robot():
        if engine_started.wait(60):
            result["rc"] = bridge.main(["--namespace", "/example", "--listen", endpoint,
                                        "--duration", "4"])

    thread = threading.Thread(target=robot)
    thread.start()

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


def test_shipped_sample_recording_is_what_the_generator_writes():
    lines, truth = _load("make_sample_recording").rows()
    assert (EXAMPLES / "sample-handover.csv").read_text().splitlines() == lines
    assert json.loads((EXAMPLES / "sample-handover.truth.json").read_text()) == truth


def test_gazebot_phases_runs_on_the_sample_recording_and_finds_its_handover(capsys):
    from gazebot.apps.cli import main

    assert main(["phases", str(EXAMPLES / "sample-handover.csv"), "--json"]) == 0
    segments = json.loads(capsys.readouterr().out)["segments"]
    truth = json.loads((EXAMPLES / "sample-handover.truth.json").read_text())["handovers"][0]
    assert [s["phase"] for s in segments] == ["reach", "transfer", "retreat"]
    reach, transfer, _ = segments
    assert abs(reach["start"] - truth["reach_start"]) < 0.1
    assert abs(transfer["start"] - truth["transfer_start"]) < 0.1
    assert abs(transfer["end"] - truth["transfer_end"]) < 0.1


def test_register_extensions_example_adds_a_phase_method_and_a_controller_from_outside():
    from gazebot.apps.controllers import CONTROLLERS
    from gazebot.apps.sim.scene_config import SceneConfig
    from gazebot.core.phases.methods import PHASE_METHODS

    example = _load("register_extensions")
    try:
        lines = example.main()
        online = [line.split()[1] for line in lines if line.startswith("online")]
        assert online == ["reach_started", "transfer_started", "retreat_started"]
        starts = {line.split()[0]: float(line.split()[1]) for line in lines[1:4]}
        truth = float(lines[0].split("transfer")[1].split()[0])
        assert starts["reach"] < starts["transfer"] < starts["retreat"]
        assert abs(starts["transfer"] - truth) < 0.4
        assert lines[-1] == "straight: [1.0, 0.0, 0.0] m/s"
        # Registered names are accepted wherever the built-ins are: configs and the CLI.
        scene = SceneConfig.model_validate({"controller": {"reach_controller": "straight"}})
        assert scene.controller.reach_controller == "straight"
        from gazebot.apps.cli import build_parser

        args = build_parser().parse_args(["phases", "x.csv", "--method", "closest-approach"])
        assert args.method == "closest-approach"
    finally:
        PHASE_METHODS.unregister("closest-approach")
        CONTROLLERS.unregister("straight")


def test_an_installed_extension_reaches_the_real_gazebot_cli_through_its_entry_points(
    monkeypatch, capsys
):
    """A package that declares the example's classes as entry points (groups
    ``gazebot.phase_methods`` and ``gazebot.controllers``) is usable by name in the real
    ``gazebot`` command, with no code of its own run first."""
    import importlib.metadata as md

    from gazebot.apps.cli import build_parser, main
    from gazebot.apps.controllers import CONTROLLERS
    from gazebot.core.phases.methods import PHASE_METHODS

    installed = [
        md.EntryPoint("closest-approach", "register_extensions:ClosestApproach",
                      "gazebot.phase_methods"),
        md.EntryPoint("straight", "register_extensions:Straight", "gazebot.controllers"),
    ]
    monkeypatch.syspath_prepend(str(EXAMPLES))
    monkeypatch.setattr("gazebot.core.registry.importlib.metadata.entry_points",
                        lambda group=None: [ep for ep in installed if ep.group == group])
    PHASE_METHODS.reload_entry_points()
    CONTROLLERS.reload_entry_points()
    try:
        parser = build_parser()
        assert parser.parse_args(["demo", "--controller", "straight"]).controller == "straight"
        assert main(["phases", str(EXAMPLES / "sample-handover.csv"),
                     "--method", "closest-approach", "--json"]) == 0
        segments = json.loads(capsys.readouterr().out)["segments"]
        assert [s["phase"] for s in segments] == ["reach", "transfer", "retreat"]
        with pytest.raises(SystemExit):
            parser.parse_args(["demo", "--controller", "curved"])  # not installed
    finally:
        monkeypatch.undo()
        PHASE_METHODS.reload_entry_points()
        CONTROLLERS.reload_entry_points()
    assert "straight" not in CONTROLLERS.names()
