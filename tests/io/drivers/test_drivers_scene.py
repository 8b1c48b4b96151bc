"""The engine node's scene on the bus during a simulated handover: ``/tf`` with the head joints
it commands, the latched ``gaze`` frame on ``/tf_static`` and ``markers``, taken off the wire as
CDR and decoded by mcap-ros2-support with the definitions rosbags generates (not gazebot's
codec)."""

from __future__ import annotations

import threading

import pytest
import zenoh.ext as zext
from drivers_fakes import wait_until
from rosbags.typesys import Stores, get_typestore
from test_drivers_e2e import sim, start_engine_node, start_sim_node  # noqa: F401 - fixture

from gazebot.io.ros2 import topics
from gazebot.io.ros2.markers import IDS, MARKER_ARRAY

pytestmark = pytest.mark.zenoh
JAZZY = get_typestore(Stores.ROS2_JAZZY)


def decoder(type_name: str):
    dynamic = pytest.importorskip("mcap_ros2._dynamic", reason="mcap-ros2-support not installed")
    text, _ = JAZZY.generate_msgdef(type_name, ros_version=2)
    return dynamic.generate_dynamic(type_name, text)[type_name]


class Raw:
    """CDR samples of one topic, as any Zenoh subscriber gets them. The subscriber is undeclared
    when the bus closes: on eclipse-zenoh 1.5, an advanced subscriber left to the session's
    close keeps its callback thread, and the test run never exits."""

    def __init__(self, bus, session, key: str, latched: bool = False) -> None:
        self.lock = threading.Lock()
        self.data: list[bytes] = []
        if latched:
            self.sub = zext.declare_advanced_subscriber(
                session, key, self._on, subscriber_detection=True,
                history=zext.HistoryConfig(detect_late_publishers=True, max_samples=1))
        else:
            self.sub = session.declare_subscriber(key, self._on)
        bus.closers.append(self.sub.undeclare)

    def _on(self, sample) -> None:
        with self.lock:
            self.data.append(sample.payload.to_bytes())

    def all(self) -> list[bytes]:
        with self.lock:
            return list(self.data)


def test_the_engine_publishes_tf_and_markers_during_a_handover(bus, sim):  # noqa: F811
    sim_node, ep, sim_thread, _ = start_sim_node(bus, sim)
    engine_node, drv, *_ = start_engine_node(bus)
    assert engine_node.scene is not None
    assert wait_until(lambda: ep.peers().get("engine") and drv.peers().get("sim"))
    assert engine_node.ready.wait(30)
    watcher = bus.connector()
    ns = bus.names.namespace.strip("/")
    markers = Raw(bus, watcher, f"0/{ns}/markers/*/*")
    tf = Raw(bus, watcher, "0/tf/*/*")
    read_markers, read_tf = decoder(MARKER_ARRAY), decoder(topics.TF.type)

    def phases() -> set[str]:
        return {m.text for d in markers.all() for m in read_markers(d).markers
                if m.id == IDS["phase"]}

    # The reach's markers come within a wall-clock second of the start: the engine's
    # publishers must route to the watcher first (a loaded machine may take longer).
    scene = engine_node.scene
    assert wait_until(lambda: scene._markers._pub.matching_status.matching
                      and scene._tf._pub.matching_status.matching)
    sim_thread.start()
    assert wait_until(lambda: tf.all() and "transfer" in phases(), timeout=120, poll=0.25)
    # /tf_static was sent once, before this subscriber: it is latched
    static = Raw(bus, watcher, "0/tf_static/*/*", latched=True)
    assert wait_until(static.all, timeout=20)

    (gaze,) = read_tf(static.all()[0]).transforms
    assert gaze.child_frame_id == "gaze" and gaze.header.frame_id.startswith("gazebot/")
    frames = {t.child_frame_id for t in read_tf(tf.all()[-1]).transforms}
    assert {"gazebot/head_pan", gaze.header.frame_id} <= frames
    arrays = [read_markers(d) for d in markers.all()]
    last = {m.id: m for m in arrays[-1].markers}
    assert set(last) == set(IDS.values())
    assert {m.header.frame_id for m in arrays[-1].markers} == {bus.names.base_frame}
    assert {"reach", "transfer"} <= phases()
    rays = [m for a in arrays for m in a.markers if m.id == IDS["gaze_ray"] and m.action == 0]
    assert rays and all(len(r.points) == 2 for r in rays)
    assert any(m.action == 0 for a in arrays for m in a.markers if m.id == IDS["giver_hand"])
