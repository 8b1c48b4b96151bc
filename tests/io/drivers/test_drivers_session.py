"""The bus' configuration: endpoints, modes and the Zenoh configuration they become."""

from __future__ import annotations

import pytest

from gazebot.io.drivers.session import BusConfig


def test_bus_config_rejects_bad_endpoints_and_modes():
    with pytest.raises(ValueError, match="endpoint"):
        BusConfig(listen=("127.0.0.1:7447",))
    with pytest.raises(ValueError, match="router"):
        BusConfig(mode="client", connect=())
    with pytest.raises(ValueError, match="mode"):
        BusConfig(mode="broker")
    cfg = BusConfig().zenoh_config()
    assert '"tcp/127.0.0.1:7447"' in cfg.get_json("listen/endpoints")
    assert cfg.get_json("scouting/multicast/enabled") == "false"
    assert BusConfig(mode="router").zenoh_config().get_json("mode") == '"router"'
