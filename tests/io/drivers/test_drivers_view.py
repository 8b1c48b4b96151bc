"""``gazebot view`` during a simulated handover, seen by a Foxglove WebSocket client written here
from the protocol's spec (``foxglove.websocket.v1``: JSON ``advertise`` / ``subscribe``, binary
message data: opcode 0x01, uint32 subscription id, uint64 timestamp, payload), not gazebot's
code; the payloads are decoded by mcap-ros2-support from the schemas the server advertised."""

from __future__ import annotations

import contextlib
import json
import struct
import threading

import pytest
from drivers_fakes import wait_until
from test_drivers_e2e import sim, start_engine_node, start_sim_node  # noqa: F401 - fixture

from gazebot.io.ros2 import topics
from gazebot.io.ros2.markers import IDS

pytestmark = pytest.mark.zenoh
foxglove = pytest.importorskip("foxglove", reason="foxglove-sdk not installed")
ws_client = pytest.importorskip("websockets.sync.client")
dynamic = pytest.importorskip("mcap_ros2._dynamic", reason="mcap-ros2-support not installed")


#: The published protocol (``foxglove.websocket.v1``) and the Foxglove SDK's name of it since
#: 0.2x (``foxglove.sdk.v1``, same messages), which is the only one foxglove-sdk 0.30 accepts.
SUBPROTOCOLS = ["foxglove.websocket.v1", "foxglove.sdk.v1"]


class FoxgloveClient:
    """The client side of the Foxglove WebSocket protocol, as far as this test needs it."""

    def __init__(self, url: str) -> None:
        self.stack = contextlib.ExitStack()
        self.ws = self.stack.enter_context(ws_client.connect(url, subprotocols=SUBPROTOCOLS))
        self.subprotocol = self.ws.subprotocol
        assert self.subprotocol in SUBPROTOCOLS
        self.channels: dict[str, dict] = {}
        self.by_sub: dict[int, str] = {}
        self.received: dict[str, list[tuple[int, bytes]]] = {}
        self.lock = threading.Lock()
        self._next = 0
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self) -> None:
        try:
            for frame in self.ws:
                if isinstance(frame, bytes):
                    assert frame[0] == 0x01  # message data
                    sub, stamp = struct.unpack_from("<IQ", frame, 1)
                    with self.lock:
                        topic = self.by_sub[sub]
                        self.received.setdefault(topic, []).append((stamp, frame[13:]))
                    continue
                msg = json.loads(frame)
                if msg["op"] == "advertise":
                    with self.lock:
                        for ch in msg["channels"]:
                            self.channels[ch["topic"]] = ch
        except Exception:  # the connection closed at teardown
            pass

    def subscribe(self, topic: str) -> None:
        with self.lock:
            ch = self.channels[topic]
            sub = self._next
            self._next += 1
            self.by_sub[sub] = topic
        self.ws.send(json.dumps({"op": "subscribe",
                                 "subscriptions": [{"id": sub, "channelId": ch["id"]}]}))

    def messages(self, topic: str) -> list:
        """The topic's messages, decoded with the schema the server advertised."""
        with self.lock:
            ch = self.channels[topic]
            data = [d for _, d in self.received.get(topic, [])]
        assert ch["encoding"] == "cdr" and ch["schemaEncoding"] == "ros2msg"
        read = dynamic.generate_dynamic(ch["schemaName"], ch["schema"])[ch["schemaName"]]
        return [read(d) for d in data]

    def count(self, topic: str) -> int:
        with self.lock:
            return len(self.received.get(topic, []))


def test_a_foxglove_client_sees_the_markers_and_the_phase_of_a_running_handover(bus, sim):  # noqa: F811
    from gazebot.apps.cli.view import LiveView

    sim_node, ep, sim_thread, _ = start_sim_node(bus, sim)
    engine_node, drv, *_ = start_engine_node(bus)
    assert wait_until(lambda: ep.peers().get("engine") and drv.peers().get("sim"))
    assert engine_node.ready.wait(30)
    view = LiveView(bus.connector(), bus.names, port=0)
    bus.closers.append(view.close)
    client = FoxgloveClient(f"ws://127.0.0.1:{view.port}")
    bus.closers.append(client.stack.close)
    markers = bus.names.resolve(topics.MARKERS.name)
    phase = bus.names.resolve(topics.PHASE.name)
    assert wait_until(lambda: {markers, phase, "/tf", "/tf_static"} <= set(client.channels),
                      timeout=20)
    client.subscribe(markers)
    client.subscribe(phase)
    sim_thread.start()
    assert wait_until(lambda: engine_node.phase == "done", timeout=120)
    # the engine's last phase reaches the client a moment after the engine decided it
    assert wait_until(lambda: client.count(markers) > 20
                      and [m.phase for m in client.messages(phase)][-1:] == ["done"],
                      timeout=30, poll=0.25)
    # /tf_static was published once, long before: latched, it still reaches a late subscriber
    client.subscribe("/tf_static")
    assert wait_until(lambda: client.count("/tf_static"), timeout=20)

    phases = [m.phase for m in client.messages(phase)]
    assert phases[-1] == "done" and "transfer" in phases
    arrays = client.messages(markers)
    texts = [m.text for a in arrays for m in a.markers if m.id == IDS["phase"]]
    assert {"reach", "transfer"} <= set(texts)
    hands = [m for a in arrays for m in a.markers if m.id == IDS["giver_hand"] and m.action == 0]
    assert hands and all(m.header.frame_id == bus.names.base_frame for m in hands)
    (static,) = client.messages("/tf_static")[:1]
    assert static.transforms[0].child_frame_id == "gaze"
    assert view.ros.drops.total == 0
