"""The bus inspector's pieces that need no bus: rate statistics as ``ros2 topic hz`` reports
them, messages as plain data (``ros2 topic echo``), and the topics of a graph."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.io.drivers.rmw.graph import Entity, Graph
from gazebot.io.drivers.rmw.introspect import (
    RateWindow,
    json_safe,
    message_to_plain,
    topic_summaries,
)
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2 import type_info, typestore
from gazebot.io.ros2.codec import Codec


def test_rate_window_reports_the_mean_rate_and_the_periods_spread():
    w = RateWindow(window=100)
    assert w.stats() is None
    w.tick(0.0)
    assert w.stats() is None
    for t in (0.1, 0.3, 0.4):  # periods 0.1, 0.2, 0.1
        w.tick(t)
    s = w.stats()
    assert s.window == 3 and w.count == 4
    assert s.rate == pytest.approx(3 / 0.4)
    assert (s.min_period, s.max_period) == pytest.approx((0.1, 0.2))
    assert s.std_dev == pytest.approx(np.std([0.1, 0.2, 0.1]))


def test_rate_window_keeps_only_the_last_periods():
    w = RateWindow(window=2)
    for t in (0.0, 1.0, 1.5, 2.0):  # the window: 1.0 -> 1.5 -> 2.0
        w.tick(t)
    s = w.stats()
    assert s.window == 2 and s.rate == pytest.approx(2.0) and s.max_period == pytest.approx(0.5)
    with pytest.raises(ValueError, match="at least 1"):
        RateWindow(window=0)


def _phase():
    store = typestore()
    T = store.types
    return T[cv.HANDOVER_PHASE](
        header=T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=3, nanosec=5),
                                         frame_id="world"),
        phase="reach", source="tracking",
        phase_start=T["builtin_interfaces/msg/Time"](sec=1, nanosec=0),
        expected_end=T["builtin_interfaces/msg/Time"](sec=0, nanosec=0))


def test_a_message_as_plain_data_has_its_fields_in_order_without_constants():
    plain = message_to_plain(_phase())
    assert plain == {"header": {"stamp": {"sec": 3, "nanosec": 5}, "frame_id": "world"},
                     "phase": "reach", "source": "tracking",
                     "phase_start": {"sec": 1, "nanosec": 0},
                     "expected_end": {"sec": 0, "nanosec": 0}}
    assert list(plain) == ["header", "phase", "source", "phase_start", "expected_end"]


def test_arrays_become_lists_and_long_ones_are_cut():
    codec = Codec.for_type(typestore(), cv.COMPRESSED_IMAGE)
    T = typestore().types
    img = T[cv.COMPRESSED_IMAGE](header=T["std_msgs/msg/Header"](
        stamp=T["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id="f" * 10),
        format="jpeg", data=np.arange(6, dtype=np.uint8))
    decoded = codec.decode(codec.encode(img))  # as a subscription hands it over
    assert message_to_plain(decoded)["data"] == [0, 1, 2, 3, 4, 5]
    cut = message_to_plain(decoded, truncate=4)
    assert cut["data"] == [0, 1, 2, 3, "..."] and cut["header"]["frame_id"] == "ffff..."
    assert cut["format"] == "jpeg"


def test_json_safe_spells_non_finite_numbers():
    assert json_safe({"a": [math.nan, math.inf, -math.inf, 1.5]}) == {
        "a": ["nan", "inf", "-inf", 1.5]}


def test_topic_summaries_group_endpoints_by_topic():
    store = typestore()
    info = type_info(store, cv.POINT_STAMPED)
    g = Graph(0)
    for i, (kind, node, topic) in enumerate([("MP", "engine", "/gazebot/gaze_target"),
                                             ("MS", "sim", "/gazebot/gaze_target"),
                                             ("MS", "display", "/gazebot/gaze_target"),
                                             ("MP", "sim", "/gazebot/tracking/giver_hand")]):
        e = Entity(0, "ab", i, i + 10, kind, "/gazebot", node, topic=topic,
                   dds_type=info.dds_name, type_hash=info.hash)
        g.update(e.token(), True)
    g.update(Entity(0, "ab", 9, 9, "NN", "/gazebot", "engine").token(), True)
    target, hand = topic_summaries(g)
    assert target.name == "/gazebot/gaze_target" and target.types == (cv.POINT_STAMPED,)
    assert [e.node for e in target.publishers] == ["engine"]
    assert [e.node for e in target.subscribers] == ["display", "sim"]
    assert hand.name == "/gazebot/tracking/giver_hand" and not hand.subscribers
