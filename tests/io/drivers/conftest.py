"""Fixtures for the driver tests: Zenoh sessions on fresh loopback ports, closed at teardown."""

from __future__ import annotations

import itertools
import threading

import pytest
from drivers_fakes import free_port

from gazebot.io.drivers.rmw.names import Names
from gazebot.io.drivers.session import EPHEMERAL_ENDPOINT, BusConfig, open_session

_ids = itertools.count()


class Bus:
    """Opens sessions of one test's bus: the robot side listens on a fresh port, the others
    connect to it; every session is closed at teardown. Each test has its own namespace."""

    def __init__(self) -> None:
        self.names = Names(f"/t{next(_ids)}")
        self.port = free_port()
        self.endpoint = f"tcp/127.0.0.1:{self.port}"
        self.sessions: list = []
        self.closers: list = []
        self.threads: list[threading.Thread] = []

    def listener(self):
        return self._open(BusConfig(self.names, listen=(self.endpoint,)))

    def connector(self):
        # Connectors listen on an ephemeral port too, so gossip meshes them with each other.
        return self._open(
            BusConfig(self.names, listen=(EPHEMERAL_ENDPOINT,), connect=(self.endpoint,))
        )

    def config(self, **kw) -> BusConfig:
        return BusConfig(self.names, **kw)

    def _open(self, cfg: BusConfig):
        session = open_session(cfg)
        self.sessions.append(session)
        return session

    def close(self) -> None:
        for fn in reversed(self.closers):
            fn()
        for th in self.threads:
            th.join(timeout=5)
        for s in self.sessions:
            if not s.is_closed():
                s.close()


@pytest.fixture
def bus():
    b = Bus()
    yield b
    b.close()
