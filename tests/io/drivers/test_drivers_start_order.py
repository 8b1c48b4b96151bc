"""Start order does not matter (issue 32): ``gazebot sim`` holds its scene's clock until an
engine owns the robot, so an engine started seconds after the simulator still sees the whole
handover; one started first simply finds the robot when it comes.

The gap between the two starts is GAP s of wall time with the simulator at SPEED x real time:
GAP * SPEED simulated seconds, longer than the default scene's whole handover, so a simulator
that did not wait would be done before the late engine joined.
"""

from __future__ import annotations

import json
import threading
import time
from types import SimpleNamespace

import pytest
from drivers_fakes import Recorder, wait_until
from test_drivers_e2e import PHASES, start_engine_node

from gazebot.apps.cli import main
from gazebot.io.drivers.session import EPHEMERAL_ENDPOINT
from gazebot.io.ros2 import convert, topics

pytestmark = pytest.mark.zenoh

GAP = 5.0  # s of wall time between the two starts
SPEED = 3.0  # the simulator's pace: GAP * SPEED = 15 simulated s, more than the handover


def start_sim(bus, capsys_out: list, *extra: str) -> threading.Thread:
    """``gazebot sim`` in a thread, joining the test's bus through its hub."""

    def run() -> None:
        capsys_out.append(
            main(
                [
                    "sim",
                    "--headless",
                    "--namespace",
                    bus.names.namespace,
                    "--speed",
                    str(SPEED),
                    "--listen",
                    EPHEMERAL_ENDPOINT,
                    "--connect",
                    bus.endpoint,
                    "--duration",
                    "45",
                    "--json",
                    *extra,
                ]
            )
        )

    th = threading.Thread(target=run, name="gazebot-sim", daemon=True)
    th.start()
    bus.threads.append(th)
    return th


def engine_phases(hub) -> Recorder:
    """The phase events every node publishes, seen from the hub (a third party on the bus)."""
    return Recorder(hub, topics.EVENTS, convert.event_of)


@pytest.fixture
def hub(bus):
    """The meeting point both nodes connect to (as a router is in the README's example)."""
    return SimpleNamespace(names=bus.names, session=bus.listener())


@pytest.mark.parametrize("first", ["sim", "engine"])
def test_sim_and_engine_complete_the_handover_whichever_starts_first(bus, hub, capsys, first):
    events = engine_phases(hub)
    status: list[int] = []
    if first == "sim":
        sim = start_sim(bus, status, "--wait-timeout", "300")
        time.sleep(GAP)
        assert sim.is_alive()  # still waiting for an engine, its scene not started
        start_engine_node(bus)
    else:
        start_engine_node(bus)
        time.sleep(GAP)
        sim = start_sim(bus, status, "--wait-timeout", "300")
    sim.join(timeout=600)
    assert status == [0], capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["handover_done"] and summary["applied"]["head"] > 0
    # the engine started before any tracking sample: its node event says it has no clock yet
    started = events.where(source="engine", kind="node_started")
    assert len(started) == 1 and started[0].t == 0.0 and started[0].info["clock"] == "none"
    # the engine saw the handover from its start: every phase, in order, ending handover_done
    assert wait_until(
        lambda: [m.kind for m in events.where(source="engine", category="phase")] == PHASES,
        timeout=120,
    ), [m.kind for m in events.msgs]


def test_sim_without_an_engine_gives_up_after_the_wait_timeout_in_one_line(bus, capsys):
    status: list[int] = []
    start_sim(bus, status, "--wait-timeout", "1").join(timeout=300)
    assert status == [2]
    err = [line for line in capsys.readouterr().err.splitlines() if "error" in line]
    assert err == [
        f"gazebot sim: error: no gaze engine owned the robot under {bus.names.namespace} "
        "within 1 s: start `gazebot run` on the same bus (or use --with-engine, or --no-wait "
        "to start the scene anyway)"
    ]
