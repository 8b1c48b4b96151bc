"""A node that must stop exits non-zero and says why in one line (issue 21): a second engine on
a robot (``gazebot run``, status 3) and an in-process engine that stops (``gazebot sim
--with-engine``: the simulation stops with it, status 1, instead of running on without gaze)."""

from __future__ import annotations

import pytest
from drivers_fakes import wait_until
from test_drivers_faults import robot_side

from gazebot.apps.cli import main
from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver

pytestmark = pytest.mark.zenoh


def test_gazebot_run_on_a_robot_another_engine_owns_exits_3_with_one_line(bus, capsys):
    ep = robot_side(bus)
    owner = ZenohRobotDriver(bus.connector(), bus.names, "engine")
    bus.closers.append(owner.close)
    owner.claim()
    assert wait_until(lambda: len(ep.owners.claims()) == 1)
    rc = main(["run", "--robot", "sawyer", "--namespace", bus.names.namespace,
               "--connect", bus.endpoint, "--duration", "20", "--no-robot-warning", "60"])
    assert rc == 3
    err = [line for line in capsys.readouterr().err.splitlines() if "error" in line]
    assert len(err) == 1 and err[0].startswith("gazebot run: error: another engine, engine ")
    assert "--standby" in err[0]


def test_sim_with_engine_stops_with_one_line_and_status_1_when_its_engine_stops(
        bus, capsys, monkeypatch):
    from gazebot.io.drivers.engine_node import EngineNode

    def broken_run(self, duration=None, stop=None):
        raise RuntimeError("engine node broke\non two lines")

    monkeypatch.setattr(EngineNode, "run", broken_run)
    rc = main(["sim", "--headless", "--with-engine", "--namespace", bus.names.namespace,
               "--listen", bus.endpoint, "--duration", "60", "--json"])
    assert rc == 1
    captured = capsys.readouterr()
    err = [line for line in captured.err.splitlines() if "error" in line]
    assert err == ["gazebot sim: error: the in-process engine stopped (RuntimeError: engine "
                   "node broke on two lines); the simulation stopped with it"]
    assert '"t": ' in captured.out and '"handover_done": false' in captured.out
