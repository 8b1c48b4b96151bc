"""The rmw_zenoh wire's pieces, pinned against rmw_zenoh's own layouts (``docs/design.md``,
``liveliness_utils.cpp``, ``attachment_helpers.cpp``) and an independent implementation
(zenoh-ros2-sdk) where one is installed."""

from __future__ import annotations

import struct

import pytest

from gazebot.io.drivers.rmw.attachment import Attachment, AttachmentError, gid_of
from gazebot.io.drivers.rmw.graph import Entity, Graph
from gazebot.io.drivers.rmw.names import Names, parse_remap
from gazebot.io.drivers.rmw.qos import BEST_EFFORT, TRANSIENT_LOCAL, QosProfile

STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"


def test_topic_names_resolve_under_the_namespace_and_remap():
    names = Names.from_rules("/gazebot", ["gaze_target:=/robot/look_at",
                                          "/gazebot/head/command:=neck/goal"])
    assert names.resolve("tracking/giver_hand") == "/gazebot/tracking/giver_hand"
    assert names.resolve("/joint_states") == "/joint_states"
    assert names.resolve("gaze_target") == "/robot/look_at"
    assert names.resolve("head/command") == "/gazebot/neck/goal"
    assert names.key("/chatter", "std_msgs::msg::dds_::String_", STRING_HASH) == \
        f"0/chatter/std_msgs::msg::dds_::String_/{STRING_HASH}"
    for bad in ("gaze_target", "a:=b:=c", "a:=1b", ":=b"):
        with pytest.raises(ValueError, match="remap"):
            parse_remap(bad)
    for bad in ("gazebot", "/a//b", "/1a", "/a-b"):
        with pytest.raises(ValueError, match="namespace"):
            Names(bad)
    with pytest.raises(ValueError, match="domain"):
        Names(domain_id=300)


def test_qos_encodes_as_rmw_zenoh_elides_its_defaults():
    # rmw_zenoh's talker example (keep last 7, otherwise default)
    assert QosProfile(depth=7).encode() == "::,7:,:,:,,"
    assert QosProfile(depth=42).encode() == "::,:,:,:,,"
    assert QosProfile().encode() == "::,10:,:,:,,"
    custom = QosProfile(reliability=BEST_EFFORT, durability=TRANSIENT_LOCAL, depth=1,
                        deadline=(1, 500))
    assert custom.encode() == "2:1:,1:1,500:,:,,"
    assert QosProfile.decode(custom.encode()) == custom
    with pytest.raises(ValueError):
        QosProfile.decode("::,10")


def test_liveliness_tokens_follow_rmw_zenoh_and_parse_back():
    node = Entity(0, "aac3178e146ba6f1fc6e6a4085e77f21", 0, 0, "NN", "/", "talker")
    assert node.token() == "@ros2_lv/0/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/talker"
    pub = Entity(0, "aac3178e146ba6f1fc6e6a4085e77f21", 0, 11, "MP", "/", "talker",
                 topic="/chatter", dds_type="std_msgs::msg::dds_::String_", type_hash=STRING_HASH,
                 qos=QosProfile(depth=7))
    assert pub.token() == (
        "@ros2_lv/0/aac3178e146ba6f1fc6e6a4085e77f21/0/11/MP/%/%/talker/%chatter/"
        f"std_msgs::msg::dds_::String_/{STRING_HASH}/::,7:,:,:,,")
    assert Entity.parse(pub.token()) == pub
    sub = Entity(3, "ab", 1, 5, "MS", "/gazebot", "engine", topic="/gazebot/tracking/giver_hand",
                 dds_type="geometry_msgs::msg::dds_::PointStamped_", type_hash="RIHS01_x",
                 qos=QosProfile())
    assert "/%gazebot/engine/%gazebot%tracking%giver_hand/" in sub.token()
    assert Entity.parse(sub.token()).ros_type == "geometry_msgs/msg/PointStamped"
    graph = Graph(3)
    assert graph.update(sub.token(), True) == Entity.parse(sub.token())
    assert graph.update("@ros2_lv/3/garbage", True) is None and graph.bad_tokens == 1
    assert graph.update(pub.token(), True) is None  # domain 0: not ours
    assert graph.topics() == {"/gazebot/tracking/giver_hand": {
        ("geometry_msgs/msg/PointStamped", "RIHS01_x")}}
    graph.update(sub.token(), False)
    assert graph.topics() == {}


def test_attachment_is_two_int64_and_a_16_byte_gid_as_zenoh_ext_serializes_them():
    gid = bytes(range(16))
    raw = Attachment(7, 1_700_000_000_123_456_789, gid).encode()
    assert raw == struct.pack("<qq", 7, 1_700_000_000_123_456_789) + b"\x10" + gid
    assert Attachment.decode(raw) == Attachment(7, 1_700_000_000_123_456_789, gid)
    for bad in (raw[:-1], raw + b"\x00", raw[:16] + b"\x0f" + gid):
        with pytest.raises(AttachmentError):
            Attachment.decode(bad)


def test_attachment_matches_zenoh_ext_serialization():
    zenoh_ext = pytest.importorskip("zenoh.ext")
    gid = bytes(range(16))
    ours = Attachment(3, 42, gid).encode()
    theirs = zenoh_ext.z_serialize((zenoh_ext.Int64(3), zenoh_ext.Int64(42), gid)).to_bytes()
    assert ours == theirs


def test_attachment_and_tokens_match_an_independent_implementation():
    sdk = pytest.importorskip("zenoh_ros2_sdk", reason="zenoh-ros2-sdk (test dependency)")
    from zenoh_ros2_sdk.attachment import Attachment as SdkAttachment
    from zenoh_ros2_sdk.entity import EndpointEntity, EntityKind, NodeEntity
    from zenoh_ros2_sdk.keyexpr import endpoint_liveliness_keyexpr, node_liveliness_keyexpr

    gid = gid_of("@ros2_lv/0/ab/0/1/MP/%/%/n/%t/std_msgs::msg::dds_::String_/x/::,10:,:,:,,")
    assert len(gid) == 16
    raw = Attachment(9, 123, gid).encode()
    assert SdkAttachment.from_bytes(raw) == SdkAttachment(9, 123, gid)
    node = NodeEntity(domain_id=0, session_id="ab12", node_id=2, node_name="engine",
                      namespace="/gazebot")
    ours_node = Entity(0, "ab12", 2, 2, "NN", "/gazebot", "engine")
    assert ours_node.token() == node_liveliness_keyexpr(node)
    ep = EndpointEntity(node=node, entity_id=5, kind=EntityKind.PUBLISHER,
                        name="/gazebot/gaze_target",
                        dds_type_name="geometry_msgs::msg::dds_::PointStamped_",
                        type_hash="RIHS01_x", qos=sdk.qos.QosProfile().encode())
    ours = Entity(0, "ab12", 2, 5, "MP", "/gazebot", "engine", topic="/gazebot/gaze_target",
                  dds_type="geometry_msgs::msg::dds_::PointStamped_", type_hash="RIHS01_x",
                  qos=QosProfile())
    assert ours.token() == endpoint_liveliness_keyexpr(ep)


def test_gid_is_xxh3_128_of_the_token_low_half_first():
    import xxhash

    token = "@ros2_lv/0/ab/0/1/NN/%/%/talker"
    h = xxhash.xxh3_128(token.encode()).intdigest()
    assert gid_of(token) == h.to_bytes(16, "little")
