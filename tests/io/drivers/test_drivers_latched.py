"""Transient local (latched) topics as rmw_zenoh does them (``rmw_publisher_data.cpp``,
``rmw_subscription_data.cpp``: zenoh-ext's AdvancedPublisher with a cache of ``depth`` samples
and publisher detection, AdvancedSubscriber querying the history and detecting late
publishers), against a peer written here from rmw_zenoh's source with zenoh-ext and rosbags,
not with gazebot's code."""

from __future__ import annotations

import logging
import struct
import threading
import time

import numpy as np
import pytest
import zenoh
import zenoh.ext as zext
from drivers_fakes import wait_until
from rosbags.typesys import Stores, get_typestore

from gazebot.core.types import Phase
from gazebot.io.drivers.rmw.attachment import Attachment
from gazebot.io.drivers.rmw.graph import Entity, Graph
from gazebot.io.drivers.rmw.node import RosNode
from gazebot.io.drivers.rmw.qos import TRANSIENT_LOCAL, VOLATILE, QosProfile
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2 import topics
from gazebot.io.ros2.typestore import typestore

JAZZY = get_typestore(Stores.ROS2_JAZZY)
STRING, TF = "std_msgs/msg/String", "tf2_msgs/msg/TFMessage"
#: rmw_zenoh's token QoS chunk of robot_state_publisher's publisher: reliable, transient local,
#: keep last 1 (``qos_to_keyexpr``, defaults elided).
LATCHED_CHUNK = ":1:,1:,:,:,,"


class RmwZenohPeer:
    """A node that declares and publishes as rmw_zenoh_cpp does, written from its source."""

    def __init__(self, session: zenoh.Session, node: str = "robot_state_publisher") -> None:
        self.session = session
        self.zid = str(session.info.zid())
        self.node = node
        self.tokens = [session.liveliness().declare_token(
            f"@ros2_lv/0/{self.zid}/0/0/NN/%/%/{node}")]
        self.pubs: list = []
        self.seq = 0

    def latched_publisher(self, topic: str, type_name: str, depth: int = 1):
        dds = type_name.replace("/", "::").replace("::msg::", "::msg::dds_::") + "_"
        type_hash = JAZZY.hash_rihs01(type_name)
        key = f"0/{topic.lstrip('/')}/{dds}/{type_hash}"
        eid = len(self.pubs) + 1
        # PublisherData::make for TRANSIENT_LOCAL + RELIABLE.
        pub = zext.declare_advanced_publisher(
            self.session, key, reliability=zenoh.Reliability.RELIABLE,
            congestion_control=zenoh.CongestionControl.DROP,
            cache=zext.CacheConfig(max_samples=depth), publisher_detection=True,
            sample_miss_detection=zext.MissDetectionConfig(sporadic_heartbeat=0.5))
        qos = f":1:,{depth if depth != 42 else ''}:,:,:,,"
        self.tokens.append(self.session.liveliness().declare_token(
            f"@ros2_lv/0/{self.zid}/0/{eid}/MP/%/%/{self.node}/{topic.replace('/', '%')}/"
            f"{dds}/{type_hash}/{qos}"))
        self.pubs.append(pub)
        return pub

    def put(self, pub, type_name: str, msg: object) -> None:
        self.seq += 1
        # rmw_zenoh's attachment: int64 sequence number, int64 source timestamp, LEB128 16 + GID
        att = struct.pack("<qqB", self.seq, time.time_ns(), 16) + bytes(range(16))
        pub.put(bytes(JAZZY.serialize_cdr(msg, type_name)), attachment=att)


def _tf_static() -> object:
    T = JAZZY.types
    return T[TF](transforms=[T["geometry_msgs/msg/TransformStamped"](
        header=T["std_msgs/msg/Header"](stamp=T["builtin_interfaces/msg/Time"](sec=1, nanosec=0),
                                        frame_id="base"),
        child_frame_id="head_camera",
        transform=T["geometry_msgs/msg/Transform"](
            translation=T["geometry_msgs/msg/Vector3"](x=0.1, y=0.0, z=1.2),
            rotation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)))])


URDF = "<robot name='sawyer'>" + "<link name='l'/>" * 500 + "</robot>"


def test_latched_robot_description_and_tf_static_published_before_gazebot_are_received(bus):
    peer = RmwZenohPeer(bus.listener())
    desc = peer.latched_publisher("/robot_description", STRING)
    static = peer.latched_publisher("/tf_static", TF)
    peer.put(desc, STRING, JAZZY.types[STRING](data="<robot name='old'/>"))
    peer.put(desc, STRING, JAZZY.types[STRING](data=URDF))  # depth 1: only this one is kept
    peer.put(static, TF, _tf_static())

    node = RosNode(bus.connector(), bus.names, "engine")
    bus.closers.append(node.close)
    wait_until(lambda: node.graph.endpoints("/tf_static", "MP"))
    got: dict[str, list] = {"desc": [], "tf": []}
    lock = threading.Lock()

    def keep(name):
        def on(msg, received):
            with lock:
                got[name].append((msg, received))
        return on

    sub = node.subscription(topics.ROBOT_DESCRIPTION.name, topics.ROBOT_DESCRIPTION.type,
                            keep("desc"))
    node.subscription(topics.TF_STATIC.name, topics.TF_STATIC.type, keep("tf"))
    assert sub.entity.qos.durability == TRANSIENT_LOCAL and sub.entity.qos.depth == 1
    assert wait_until(lambda: got["desc"] and got["tf"])
    time.sleep(0.3)
    with lock:
        (msg, received), = got["desc"]
        assert msg.data == URDF
        assert received.attachment.sequence_number == 2
        assert received.attachment.gid == bytes(range(16))
        (tf, _), = got["tf"]
    assert tf.transforms[0].child_frame_id == "head_camera"
    assert tf.transforms[0].transform.translation.z == pytest.approx(1.2)
    # A message published while subscribed arrives too, once.
    peer.put(desc, STRING, JAZZY.types[STRING](data="<robot name='new'/>"))
    assert wait_until(lambda: len(got["desc"]) == 2)
    time.sleep(0.3)
    assert [m.data for m, _ in got["desc"]][1] == "<robot name='new'/>"
    assert len(got["desc"]) == 2
    assert node.drops.total == 0


def test_a_volatile_subscription_does_not_get_what_was_published_before(bus):
    peer = RmwZenohPeer(bus.listener())
    desc = peer.latched_publisher("/robot_description", STRING)
    peer.put(desc, STRING, JAZZY.types[STRING](data=URDF))
    node = RosNode(bus.connector(), bus.names, "engine")
    bus.closers.append(node.close)
    wait_until(lambda: node.graph.endpoints("/robot_description", "MP"))
    got: list = []
    node.subscription("/robot_description", STRING, lambda m, r: got.append(m),
                      qos=QosProfile(durability=VOLATILE))
    time.sleep(1.0)
    assert got == []

    def now_arrives() -> bool:  # put until the subscription's route is up (a loaded machine)
        peer.put(desc, STRING, JAZZY.types[STRING](data="now"))
        return bool(got)

    assert wait_until(now_arrives, poll=0.05) and got[0].data == "now"


def test_gazebots_latched_phase_reaches_a_subscriber_that_starts_later(bus):
    node = RosNode(bus.listener(), bus.names, "engine")
    bus.closers.append(node.close)
    pub = node.publisher(topics.PHASE.name, topics.PHASE.type)
    assert pub.entity.token().endswith("/" + LATCHED_CHUNK)
    pub.publish(cv.handover_phase(1.0, Phase.REACH, 0.5))
    pub.publish(cv.handover_phase(2.0, Phase.TRANSFER, 1.8))

    # The late subscriber, as SubscriptionData::init declares one for TRANSIENT_LOCAL depth 1.
    other = bus.connector()
    wait_until(lambda: list(other.info.peers_zid()))
    got: list = []
    key = bus.names.key_any_type(bus.names.resolve(topics.PHASE.name))
    sub = zext.declare_advanced_subscriber(
        other, key, lambda s: got.append((s.payload.to_bytes(), s.attachment.to_bytes())),
        subscriber_detection=True, recovery=zext.RecoveryConfig(heartbeat=True),
        history=zext.HistoryConfig(detect_late_publishers=True, max_samples=1))
    bus.closers.append(sub.undeclare)
    assert wait_until(lambda: got)
    time.sleep(0.3)
    (data, att), = got
    seq, _, n = struct.unpack_from("<qqB", att)
    assert (seq, n, len(att)) == (2, 16, 33)
    # rosbags' CDR deserializer, with the gazebot_msgs definitions the package ships
    assert typestore().deserialize_cdr(data, topics.PHASE.type).phase == "transfer"


def test_newer_rmw_zenoh_tokens_with_trailing_chunks_are_read_not_counted_bad():
    graph = Graph(0)
    key = ("@ros2_lv/0/aac3178e146ba6f1fc6e6a4085e77f21/0/11/MP/%/%/talker/%chatter/"
           "std_msgs::msg::dds_::String_/RIHS01_df66/:1:,1:,:,:,,/extra")
    entity = graph.update(key, True)
    assert entity is not None and graph.bad_tokens == 0
    assert entity.topic == "/chatter" and entity.qos.durability == TRANSIENT_LOCAL
    assert graph.update("@ros2_lv/0/z/0/11/MP/%/%/talker/%chatter/T", True) is None
    assert graph.bad_tokens == 1
    assert Entity.parse("@ros2_lv/0/z/0/0/NN/%/%/talker/more").node == "talker"


def _labelled(seq: int, stamp: int, gid: bytes) -> bytes:
    def item(b: bytes) -> bytes:
        return bytes([len(b)]) + b
    return b"".join(item(k) + item(v) for k, v in (
        (b"sequence_number", seq.to_bytes(8, "little")),
        (b"source_timestamp", stamp.to_bytes(8, "little")), (b"source_gid", gid)))


def test_an_old_labelled_attachment_is_read_and_warned_about_once(bus, caplog):
    att = Attachment.decode(_labelled(7, 123, bytes(16)))
    assert (att.sequence_number, att.source_timestamp, att.legacy) == (7, 123, True)
    node = RosNode(bus.listener(), bus.names, "engine")
    bus.closers.append(node.close)
    got: list = []
    node.subscription("/chatter", STRING, lambda m, r: got.append(r.attachment))
    other = bus.connector()
    wait_until(lambda: list(other.info.peers_zid()))
    key = f"0/chatter/std_msgs::msg::dds_::String_/{JAZZY.hash_rihs01(STRING)}"
    data = bytes(JAZZY.serialize_cdr(JAZZY.types[STRING](data="hi"), STRING))
    pub = other.declare_publisher(key)
    bus.closers.append(pub.undeclare)
    # a peer seen is not yet a route to its subscription: put once it matches
    assert wait_until(lambda: pub.matching_status.matching)
    with caplog.at_level(logging.WARNING, logger="gazebot.io.drivers"):
        for i in range(3):
            pub.put(data, attachment=_labelled(i + 1, 5, bytes(range(16))))
        assert wait_until(lambda: len(got) == 3)
    assert [a.sequence_number for a in got] == [1, 2, 3]
    warned = [r for r in caplog.records if "0.2.0-0.2.3" in r.getMessage()]
    assert len(warned) == 1
    assert np.all([a.legacy for a in got])
