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
import test_drivers_e2e
from drivers_fakes import Recorder, wait_until
from test_drivers_e2e import PHASES, SPEED, start_engine_node

from gazebot.apps.cli import main
from gazebot.io.drivers.session import EPHEMERAL_ENDPOINT
from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
from gazebot.io.ros2 import convert, topics

pytestmark = pytest.mark.zenoh

GAP = 20.0  # s of wall time between the two starts (the gap)
# SPEED (3, the simulator's pace, as in the other end-to-end tests): GAP * SPEED = 60 simulated
# s, far more than the default scene's handover (about 7 s).


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


class RecordingDriver(ZenohRobotDriver):
    """The engine's driver with its own events recorded on its own session from before the
    node starts (its first event is not left to the timing of the bus's connections)."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.own_events = Recorder(self, topics.EVENTS, convert.event_of)


def start_engine(bus, monkeypatch) -> Recorder:
    """The engine node of the end-to-end tests; returns the recorder of its own events."""
    monkeypatch.setattr(test_drivers_e2e, "ZenohRobotDriver", RecordingDriver)
    _, drv, *_ = start_engine_node(bus)
    return drv.own_events


def engine_phases(hub) -> Recorder:
    """The phase events every node publishes, seen from the hub (a third party on the bus)."""
    return Recorder(hub, topics.EVENTS, convert.event_of)


@pytest.fixture
def hub(bus):
    """The meeting point both nodes connect to (as a router is in the README's example)."""
    return SimpleNamespace(names=bus.names, session=bus.listener())


@pytest.mark.parametrize("first", ["sim", "engine"])
def test_sim_and_engine_complete_the_handover_whichever_starts_first(
    bus, hub, capsys, monkeypatch, first
):
    events = engine_phases(hub)
    status: list[int] = []
    if first == "sim":
        sim = start_sim(bus, status, "--wait-timeout", "300")
        time.sleep(GAP)
        assert sim.is_alive()  # still waiting for an engine, its scene not started
        own_events = start_engine(bus, monkeypatch)
    else:
        own_events = start_engine(bus, monkeypatch)
        time.sleep(GAP)
        sim = start_sim(bus, status, "--wait-timeout", "300")
    sim.join(timeout=600)
    assert status == [0], capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["handover_done"] and summary["applied"]["head"] > 0
    # the engine started before any tracking sample: its node event says it has no clock yet
    started = own_events.where(kind="node_started")
    assert len(started) == 1 and started[0].t == 0.0 and started[0].info["clock"] == "none"
    # the engine saw the handover from its start: every phase, in order, ending handover_done
    # (tracking_lost/restored, which a stalled machine may cause, are not this test's business)
    def phases() -> list[str]:
        return [m.kind for m in events.where(source="engine", category="phase")
                if m.kind in PHASES]

    assert wait_until(lambda: phases() == PHASES, timeout=120), [
        (m.source, m.kind) for m in events.msgs]


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
