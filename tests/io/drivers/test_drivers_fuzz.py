"""Fuzzing the wire (issue 21): Hypothesis over the CDR payloads of every type gazebot
subscribes to (through the handlers the nodes run on them), the rmw_zenoh attachment and the
liveliness token keys (graph and ownership). No input crashes a decoder or a handler, hangs,
or raises anything but the documented error types; decoding a payload at its topic's size cap
stays within bounded memory."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gazebot.core.types import Phase, TrackingFrame
from gazebot.io.drivers.bounds import (
    MAX_JOINTS,
    MAX_POINTS,
    check_joint_state,
    check_trajectory,
)
from gazebot.io.drivers.ownership import Claim
from gazebot.io.drivers.rmw.attachment import Attachment, AttachmentError
from gazebot.io.drivers.rmw.graph import Entity, Graph
from gazebot.io.drivers.rmw.names import Names
from gazebot.io.drivers.rmw.node import Received
from gazebot.io.drivers.rmw.qos import QosProfile
from gazebot.io.drivers.session import EPHEMERAL_ENDPOINT, BusConfig, open_session
from gazebot.io.drivers.tf_buffer import TfBuffer, add_tf_message
from gazebot.io.drivers.zenoh_display import ZenohDisplayNode
from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint
from gazebot.io.ros2 import convert, topics
from gazebot.io.ros2.codec import Codec
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.markers import MARKER_ARRAY, Scene, marker_array
from gazebot.io.ros2.typestore import typestore
from gazebot.io.ros2.values import BusEvent, EyeState, JointGoal, NodeStatus

FUZZ = settings(max_examples=150, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
STRING = "std_msgs/msg/String"


def samples() -> dict[str, object]:
    """One valid message of each type gazebot subscribes to."""
    store = typestore()
    head = JointGoal(1.0, {"head_pan": 0.1, "head_tilt": -0.2}, {}, 0.1)
    eyes = EyeState(t=1.0, yaw=0.1, pitch=0.0, blink=0.2, distance=1.0)
    status = NodeStatus(node="sim", seq=0, stamp=1.0, uptime=1.0, state="ok", tracking="ok",
                        peers={"engine": True}, dropped={"/gazebot/x": 1}, phase="reach",
                        info={"frames": 3})
    frame = TrackingFrame.make(1.0, giver_face=[1.0, 0.2, 1.5])
    return {
        convert.POINT_STAMPED: convert.point_stamped(1.0, [1.0, 0.0, 1.0], "world"),
        convert.POSE_STAMPED: convert.pose_stamped(1.0, [1.0, 0.0, 1.0], "world"),
        convert.TF_MESSAGE: convert.tracking_tf(frame, "world", {"giver_face": "mocap/face"}),
        convert.JOINT_STATE: convert.joint_state(1.0, {"head_pan": 0.1, "right_j0": 0.2}),
        convert.JOINT_TRAJECTORY: convert.joint_trajectory(head),
        convert.DIAGNOSTIC_ARRAY: convert.diagnostics(status, 1.0),
        convert.COMPRESSED_IMAGE: convert.compressed_image(np.zeros((4, 6, 3), np.uint8), 1.0,
                                                           "gaze"),
        convert.EYE_STATE: convert.eye_state(eyes, "gaze"),
        convert.HANDOVER_PHASE: convert.handover_phase(1.0, Phase.REACH, 0.5),
        convert.HANDOVER_EVENT: convert.handover_event(BusEvent(
            "sim", "robot", "robot_grasped", 1.0, 1.0, 1.0, {"planned_duration": 1.2})),
        convert.GRIPPER_STATE: convert.gripper_state(1.0, True),
        convert.LOAD_SHARE: convert.load_share(1.0, 0.5),
        STRING: store.types[STRING](data="home"),
        MARKER_ARRAY: marker_array(Scene(1.0, "reach", [0.0, 0.0, 1.2], [1.0, 0.0, 1.0]), "world"),
    }


SAMPLES = samples()
CODECS = {t: Codec.for_type(typestore(), t) for t in SAMPLES}
VALID = {t: CODECS[t].encode(m) for t, m in SAMPLES.items()}
TYPES = sorted(SAMPLES)


def test_every_subscribed_type_has_a_sample():
    assert {t.type for t in topics.ALL} | {convert.POSE_STAMPED} <= set(SAMPLES)


@st.composite
def payloads(draw) -> tuple[str, bytes]:
    """A type and bytes: random, or a valid payload of the type cut, extended, with bytes
    overwritten, or with a 32-bit length field replaced (the CDR sequence and string lengths)."""
    type_name = draw(st.sampled_from(TYPES))
    raw = bytearray(VALID[type_name])
    how = draw(st.sampled_from(["random", "cut", "extend", "flip", "length"]))
    if how == "random":
        return type_name, draw(st.binary(max_size=512))
    if how == "cut":
        return type_name, bytes(raw[: draw(st.integers(0, len(raw)))])
    if how == "extend":
        return type_name, bytes(raw) + draw(st.binary(min_size=1, max_size=256))
    if how == "flip":
        for _ in range(draw(st.integers(1, 8))):
            i = draw(st.integers(0, len(raw) - 1))
            raw[i] = draw(st.integers(0, 255))
        return type_name, bytes(raw)
    offset = draw(st.integers(4, max(4, len(raw) - 4))) // 4 * 4
    value = draw(st.sampled_from([0, 1, 7, 255, 2**16, 2**31 - 1, 2**32 - 1]))
    raw[offset:offset + 4] = value.to_bytes(4, "little")
    return type_name, bytes(raw)


@pytest.fixture(scope="module")
def nodes():
    """The robot, engine and display nodes on one session with no peer: their handlers are
    called directly with what the fuzzer decodes."""
    session = open_session(BusConfig(Names("/fuzz"), listen=(EPHEMERAL_ENDPOINT,)))
    names = Names("/fuzz", tf_frames={"giver_face": "mocap/face"})
    ep = ZenohRobotEndpoint(session, names, "sim", eye_frames=True)
    drv = ZenohRobotDriver(session, names, "engine", tf=TfBuffer())
    display = ZenohDisplayNode(session, names, "display")
    yield ep, drv, display
    for n in (display, drv, ep):
        n.close()
    session.close()


def handlers(ep, drv, display) -> dict[str, list]:
    """Every handler a node runs on a message of each type."""
    return {
        convert.POINT_STAMPED: [lambda m, rx, b=b: drv._on_point(b, m, rx)
                                for b in topics.TRACKING],
        convert.POSE_STAMPED: [lambda m, rx: drv._on_point("giver_hand", m, rx)],
        convert.TF_MESSAGE: [drv._on_tf, lambda m, rx: add_tf_message(drv.tf, m, static=True)],
        convert.JOINT_STATE: [drv._on_joints],
        convert.JOINT_TRAJECTORY: [ep._on_head, ep._on_arm, check_trajectory],
        convert.DIAGNOSTIC_ARRAY: [drv._on_status, ep._on_status],
        convert.COMPRESSED_IMAGE: [ep._on_frame],
        convert.EYE_STATE: [ep._on_eyes, display._on_eyes],
        convert.HANDOVER_PHASE: [convert.phase_of],
        convert.HANDOVER_EVENT: [drv._on_event, ep._on_event],
        convert.GRIPPER_STATE: [drv._on_gripper],
        convert.LOAD_SHARE: [drv._on_share],
        STRING: [ep._on_arm_mode],
        MARKER_ARRAY: [],  # only viewers subscribe (gazebot view forwards the bytes)
    }


@pytest.mark.zenoh
@pytest.mark.timeout(600)
@FUZZ
@given(case=payloads(), attachment=st.one_of(st.none(), st.binary(max_size=40)))
def test_decoders_and_handlers_raise_only_message_errors(nodes, case, attachment):
    type_name, raw = case
    try:
        msg = CODECS[type_name].decode(raw)
    except MessageError:
        return
    att = None
    if attachment is not None:
        try:
            att = Attachment.decode(attachment)
        except AttachmentError:
            att = None
    rx = Received(f"/fuzz/{type_name}", type_name, att)
    ep, drv, _ = nodes
    # subscriptions that check element counts before decoding get the CDR bytes
    raw_handlers = {drv._on_tf, drv._on_joints, ep._on_head, ep._on_arm}
    for handle in handlers(*nodes)[type_name]:
        try:
            if handle is convert.phase_of:
                handle(msg)
            elif handle is check_trajectory:
                handle(raw)
            else:
                handle(raw if handle in raw_handlers else msg, rx)
        except MessageError:
            pass


@FUZZ
@given(st.binary(max_size=64))
def test_attachment_decode_raises_only_attachment_errors_and_round_trips(raw):
    try:
        att = Attachment.decode(raw)
    except AttachmentError:
        return
    assert len(raw) == 33 and att.encode() == raw


TOKEN = ("@ros2_lv/0/abcdef0123/7/9/MP/%/%gazebot/engine/%gazebot%head%command/"
         "trajectory_msgs::msg::dds_::JointTrajectory_/RIHS01_" + "ab" * 32 + "/::,:,:,:,,")
CLAIM = "@gazebot_owner/0/%gazebot/1700000000000000000/abcdef0123/engine"


@st.composite
def token_keys(draw) -> str:
    """Liveliness token keys: random text, or a valid graph or ownership token with chunks
    replaced, added or removed."""
    if draw(st.booleans()):
        return draw(st.text(max_size=300))
    chunks = draw(st.sampled_from([TOKEN, CLAIM])).split("/")
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(chunks) - 1))
        op = draw(st.sampled_from(["replace", "insert", "delete"]))
        piece = draw(st.one_of(st.text(max_size=30), st.sampled_from(
            ["", "%", "-1", "99999999999999999999999", "NN", "MS", "x" * 200, ":::::", ",,"])))
        if op == "replace":
            chunks[i] = piece
        elif op == "insert":
            chunks.insert(i, piece)
        elif len(chunks) > 1:
            del chunks[i]
    return "/".join(chunks)


def test_the_valid_tokens_parse():
    assert Entity.parse(TOKEN).topic == "/gazebot/head/command"
    assert Claim.parse(CLAIM).node == "engine"


@FUZZ
@given(token_keys(), st.booleans())
def test_token_keys_raise_only_value_errors_and_the_graph_counts_bad_ones(key, alive):
    for parse in (Entity.parse, Claim.parse):
        try:
            parse(key)
        except ValueError:
            pass
    graph = Graph(0)
    before = graph.bad_tokens
    entity = graph.update(key, alive)
    assert (entity is None) or (graph.bad_tokens == before)
    chunk = key.rpartition("/")[2]
    try:
        QosProfile.decode(chunk)
    except ValueError:
        pass


def test_decoding_a_payload_at_its_cap_stays_within_bounded_memory():
    """Every 4-byte field of a valid payload set to the largest lengths, padded to the topic's
    cap: each decode allocates at most a few times the cap."""
    by_type = {t.type: t.max_bytes for t in topics.ALL}
    for type_name, raw in VALID.items():
        if type_name == MARKER_ARRAY:
            continue  # published only: no gazebot node decodes markers (view forwards the bytes)
        cap = by_type.get(type_name, 1024)
        codec = Codec.for_type(typestore(), type_name, cap)
        for offset in range(4, len(raw) - 3, 4):
            for value in (2**31 - 1, 2**32 - 1):
                bad = bytearray(raw)
                bad[offset:offset + 4] = value.to_bytes(4, "little")
                bad += b"\x01" * max(0, cap - len(bad))
                tracemalloc.start()
                try:
                    codec.decode(bytes(bad))
                except MessageError:
                    pass
                finally:
                    _, peak = tracemalloc.get_traced_memory()
                    tracemalloc.stop()
                assert peak <= 8 * cap + 1_000_000, (type_name, offset, value, peak)
    assert math.isfinite(sum(by_type.values()))


def _element_message(kind: str, names: int, points: int, name_len: int) -> tuple[str, bytes]:
    """A ``JointState`` or ``JointTrajectory`` with ``names`` joint names of ``name_len``
    characters (and ``points`` points for a trajectory), as CDR bytes."""
    if kind == "joint_state":
        msg = convert.joint_state(0.0, {"head_pan": 0.1})
        msg.name = ["j" * name_len] * names
        msg.position = np.zeros(0)
        type_name = topics.JOINT_STATES.type
    else:
        msg = convert.joint_trajectory(JointGoal(0.0, {"head_pan": 0.1}, {}, 0.1))
        msg.joint_names = ["j" * name_len] * names
        msg.points = [msg.points[0]] * points
        type_name = convert.JOINT_TRAJECTORY
    return type_name, Codec.for_type(typestore(), type_name, 1 << 24).encode(msg)


@FUZZ
@given(kind=st.sampled_from(["joint_state", "trajectory"]),
       names=st.integers(0, 4 * MAX_JOINTS), points=st.integers(0, 2 * MAX_POINTS),
       name_len=st.integers(0, 12))
def test_element_counts_decide_before_decoding_within_bounded_memory(kind, names, points,
                                                                     name_len):
    """A message with more elements than a topic needs is refused from its CDR prefix (a
    MessageError naming the field), one within the counts decodes; either way the work's peak
    memory stays within a few times the message's own size."""
    type_name, raw = _element_message(kind, names, points, name_len)
    check = check_joint_state if kind == "joint_state" else check_trajectory
    too_many = names > MAX_JOINTS or (kind == "trajectory" and points > MAX_POINTS)
    tracemalloc.start()
    try:
        try:
            check(raw)
            refused = False
            Codec.for_type(typestore(), type_name, 1 << 24).decode(raw)
        except MessageError as exc:
            refused = True
            assert "elements in" in str(exc)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert refused == too_many
    bound = 64_000 if refused else 8 * len(raw) + 1_000_000  # refused: the prefix only
    assert peak <= bound, (kind, names, points, peak)
