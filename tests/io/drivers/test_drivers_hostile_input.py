"""Crafted input on the bus, as an attacker would send it: a decode or conversion failure of any
kind is a counted drop for its topic (one log line, no traceback), an eye frame too large to
decode is refused from its header, and a finite but absurd coordinate does not kill the engine.

Real Zenoh sessions on loopback; each test has its own namespace and port.
"""

from __future__ import annotations

import logging
import threading
import zlib

import numpy as np
import pytest
import zenoh
from drivers_fakes import Recorder, wait_until

from gazebot.core.types import Event, EventKind, TrackingFrame
from gazebot.io.drivers.rmw.attachment import Attachment
from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint
from gazebot.io.ros2 import convert, topics
from gazebot.io.ros2.codec import Codec
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.typestore import typestore
from gazebot.io.ros2.values import BusEvent

pytestmark = pytest.mark.zenoh

#: 10 kB of ``[`` (within the events' size cap): json.loads recurses until RecursionError.
NESTED = "[" * 10_000


def _bomb_event() -> bytes:
    codec = Codec.for_type(typestore(), convert.HANDOVER_EVENT)
    return codec.encode(convert.handover_event(BusEvent(
        "sim", "robot", "robot_reach_started", 1.0, 1.0, 1.0, {"planned_duration": NESTED})))


def _key(node, topic) -> str:
    codec = Codec.for_type(typestore(), topic.type)
    return node.names.key(node.names.resolve(topic.name), codec.info.dds_name, codec.info.hash)


def test_a_deeply_nested_event_info_is_a_message_error_not_a_recursion_error():
    ros = Codec.for_type(typestore(), convert.HANDOVER_EVENT).decode(_bomb_event())
    with pytest.raises(MessageError, match="nested deeper"):
        convert.event_of(ros)
    with pytest.raises(MessageError, match="nested deeper"):
        convert.info_value("[" * (convert.MAX_INFO_DEPTH + 1) + "]" * (convert.MAX_INFO_DEPTH + 1))
    # gazebot's own info values still parse back
    assert convert.info_value('{"a": [1, 2]}') == {"a": [1, 2]}
    assert convert.info_value("[[") == "[["  # not JSON: a string


def test_a_crafted_event_on_a_topic_is_counted_as_a_drop_without_a_traceback(bus, caplog):
    ep = ZenohRobotEndpoint(bus.listener(), bus.names, "sim")
    bus.closers.append(ep.close)
    drv = ZenohRobotDriver(bus.connector(), bus.names, "engine")
    bus.closers.append(drv.close)
    topic = drv.names.resolve(topics.ROBOT_EVENTS.name)
    assert wait_until(lambda: any(e.topic == topic for e in ep.ros.graph.endpoints(topic, "MS")))
    # The graph may list the subscriber before the route to it is in place (puts then go
    # nowhere): send well-formed events until one arrives, then the route is there.
    probe = Event(EventKind.ROBOT_REACH_ENDED, 0.1, 0.1, {})
    assert wait_until(lambda: ep.publish_robot_event(probe) and drv.poll_events(), poll=0.05)
    with caplog.at_level(logging.WARNING, logger="gazebot.io.drivers"):
        for _ in range(20):
            # BLOCK: a burst of 100 kB puts must not be shed by Zenoh's congestion control
            ep.session.put(_key(ep, topics.ROBOT_EVENTS), _bomb_event(),
                           congestion_control=zenoh.CongestionControl.BLOCK)
        assert wait_until(lambda: drv.dropped().get(topic, 0) == 20)
    # no crafted event got through (probes still on their way may)
    assert [e.kind for e in drv.poll_events() if e.kind != "robot_reach_ended"] == []
    records = [r for r in caplog.records if topic in r.getMessage()]
    assert records and all(r.exc_info is None for r in records)
    # rate-limited: the first few per topic and node (both nodes hear robot/events), not 40
    assert len(records) <= 2 * drv.drops.log_first
    assert all(len(r.getMessage()) < 400 for r in records)  # one short line, not the payload


def test_a_handler_failing_in_any_way_is_a_counted_drop_for_its_topic(bus, caplog):
    ep = ZenohRobotEndpoint(bus.listener(), bus.names, "sim")
    bus.closers.append(ep.close)
    calls = []

    def broken(msg, rx):
        calls.append(msg)
        raise RecursionError("maximum recursion depth exceeded " + "x" * 10_000)

    sub = ep.ros.subscription("crash", "std_msgs/msg/String", broken)
    pub = ep.ros.publisher("crash", "std_msgs/msg/String")
    string = ep.ros.store.types["std_msgs/msg/String"]
    with caplog.at_level(logging.WARNING, logger="gazebot.io.drivers"):
        for i in range(5):
            pub.publish(string(data=str(i)))
        assert wait_until(lambda: ep.dropped().get(sub.topic, 0) == 5)
    assert len(calls) == 5
    assert "RecursionError" in ep.drops.reasons()[sub.topic]
    assert all(r.exc_info is None and len(r.getMessage()) < 400 for r in caplog.records)


def test_a_crafted_history_reply_is_counted_and_skipped_by_the_resync(bus):
    ep = ZenohRobotEndpoint(bus.listener(), bus.names, "sim")
    bus.closers.append(ep.close)
    drv = ZenohRobotDriver(bus.connector(), bus.names, "engine")
    bus.closers.append(drv.close)
    key = ep._history_key("liar")

    def answer(query):
        query.reply(key, _bomb_event(), attachment=Attachment(1, 0, bytes(16)).encode())

    liar = ep.session.declare_queryable(key, answer)
    bus.closers.append(liar.undeclare)
    assert wait_until(lambda: drv.event_history(timeout=2.0) == [] and drv.drops.total > 0)
    assert "nested deeper" in next(iter(drv.drops.reasons().values()))


# -- eye frames ----------------------------------------------------------------------------------


def _png_header_only(width: int, height: int) -> bytes:
    """A PNG whose header claims ``width`` x ``height`` (RGB), with a few rows of image data: a
    decoder that trusts the header allocates width*height*3 bytes first."""
    def chunk(kind: bytes, body: bytes) -> bytes:
        return (len(body).to_bytes(4, "big") + kind + body
                + zlib.crc32(kind + body).to_bytes(4, "big"))

    ihdr = width.to_bytes(4, "big") + height.to_bytes(4, "big") + bytes([8, 2, 0, 0, 0])
    rows = zlib.compress(bytes(4 * (1 + 3 * width)))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", rows)
            + chunk(b"IEND", b""))


def test_an_eye_frame_larger_than_the_bound_is_refused_from_its_header():
    bomb = _png_header_only(20000, 20000)
    with pytest.raises(MessageError, match="20000x20000"):
        convert.decode_image(bomb)
    ros = convert.RosCompressedImage(convert.header(0.0, "gaze"), "png",
                                     np.frombuffer(bomb, np.uint8))
    with pytest.raises(MessageError, match="20000x20000"):
        convert.image_of(ros)
    wide = convert.encode_image(np.zeros((4, 5000, 3), np.uint8), "jpeg")
    assert convert.image_size(wide) == ("jpeg", 5000, 4)
    with pytest.raises(MessageError, match="5000x4"):
        convert.decode_image(wide)


def test_the_image_bound_is_configurable_and_images_within_it_decode():
    img = np.zeros((48, 64, 3), np.uint8)
    img[:, :32] = (255, 0, 0)
    for fmt in ("png", "jpeg"):
        data = convert.encode_image(img, fmt)
        assert convert.image_size(data) == (fmt, 64, 48)
        assert convert.decode_image(data).shape == (48, 64, 3)
        with pytest.raises(MessageError, match="at most 32x32"):
            convert.decode_image(data, max_size=(32, 32))
    frame = convert.compressed_image(img, 0.0, "gaze", fmt="png")
    np.testing.assert_array_equal(convert.image_of(frame), img)
    with pytest.raises(MessageError, match="at most 63x48"):
        convert.image_of(frame, max_size=(63, 48))
    # other formats cv2 would decode (BMP, ...) are not eye frames
    import cv2

    bmp = cv2.imencode(".bmp", img)[1].tobytes()
    with pytest.raises(MessageError, match="neither PNG nor JPEG"):
        convert.decode_image(bmp)


# -- an absurd coordinate ------------------------------------------------------------------------


def test_the_engine_survives_a_tracking_sample_at_x_1e155_from_the_bus(bus):
    from gazebot.core.engine import GazeEngine
    from gazebot.core.runtime import GazeLoop
    from gazebot.io.drivers.engine_node import EngineNode, EngineNodeConfig

    ep = ZenohRobotEndpoint(bus.listener(), bus.names, "sim")
    bus.closers.append(ep.close)
    drv = ZenohRobotDriver(bus.connector(), bus.names, "engine")
    node = EngineNode(GazeLoop(GazeEngine.from_config("sawyer", "face-hand-face")), drv,
                      EngineNodeConfig(silence_after=1e3, heartbeat_period=0.05, resync=False))
    stop = threading.Event()
    th = threading.Thread(target=node.run, kwargs={"stop": stop}, daemon=True)

    def close():
        stop.set()
        th.join(timeout=10)
        drv.close()

    bus.closers.append(close)
    targets = Recorder(ep, topics.GAZE_TARGET, convert.point_of)
    assert wait_until(lambda: ep.peers().get("engine") and drv.peers().get("sim"))
    th.start()
    assert node.ready.wait(30)
    face = [1.0, 0.3, 1.5]

    def sample(i, hand):
        ep.publish_tracking(TrackingFrame.make(i / 120, giver_hand=hand, giver_face=face))

    for i in range(10):
        sample(i, [1.0, 0.0, 1.0])
    sample(10, [1e155, 0.0, 1.0])
    for i in range(11, 30):
        sample(i, [1.0, 0.0, 1.0])
    # the engine answered the samples after the absurd one, and its thread is alive
    assert wait_until(lambda: targets.msgs and targets.msgs[-1][0] == pytest.approx(29 / 120))
    assert th.is_alive()
    assert all(np.all(np.isfinite(p)) and np.all(np.abs(p) < 1e3) for _, p in targets.msgs)


# -- the router ----------------------------------------------------------------------------------


def test_the_router_listens_on_loopback_unless_told_to_open_up():
    from gazebot.apps.cli import build_parser
    from gazebot.apps.cli.router import router_config

    default = router_config(build_parser().parse_args(["router"]))
    assert default.mode == "router"
    assert default.listen and all(ep.startswith("tcp/127.0.0.1:") for ep in default.listen)
    opened = router_config(build_parser().parse_args(["router", "--listen", "tcp/0.0.0.0:7447"]))
    assert opened.listen == ("tcp/0.0.0.0:7447",)
