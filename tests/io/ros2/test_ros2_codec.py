"""CDR codecs: round trips, and every kind of bad payload is a MessageError."""

from __future__ import annotations

import numpy as np
import pytest

from gazebot.io.ros2 import Codec, MessageError, typestore
from gazebot.io.ros2.convert import POINT_STAMPED, point_stamped


@pytest.fixture(scope="module")
def codec() -> Codec:
    return Codec.for_type(typestore(), POINT_STAMPED)


def test_point_stamped_round_trips_through_cdr(codec: Codec) -> None:
    raw = codec.encode(point_stamped(1.5, [0.1, -0.2, 1.3], "world"))
    assert raw[:4] == b"\x00\x01\x00\x00"  # little-endian CDR, as rmw_zenoh sends it
    msg = codec.decode(raw)
    assert (msg.point.x, msg.point.y, msg.point.z) == (0.1, -0.2, 1.3)
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (1, 500_000_000)
    assert msg.header.frame_id == "world"


def test_truncated_cdr_is_a_message_error(codec: Codec) -> None:
    raw = codec.encode(point_stamped(1.0, [1, 2, 3], "world"))
    for n in (len(raw) - 1, 12, 5):
        with pytest.raises(MessageError, match="does not decode"):
            codec.decode(raw[:n])


@pytest.mark.parametrize("raw", [b"", b"\x00", b"garbage bytes, not CDR at all", b"{\"v\": 1}"])
def test_garbage_is_a_message_error(codec: Codec, raw: bytes) -> None:
    with pytest.raises(MessageError):
        codec.decode(raw)


def test_oversized_payload_is_refused_unread() -> None:
    small = Codec.for_type(typestore(), POINT_STAMPED, max_bytes=32)
    raw = small.encode(point_stamped(1.0, [1, 2, 3], "world"))
    with pytest.raises(MessageError, match="oversized"):
        small.decode(raw)


def test_a_wrong_sequence_length_is_a_message_error() -> None:
    js = Codec.for_type(typestore(), "sensor_msgs/msg/JointState")
    from gazebot.io.ros2.convert import joint_state

    raw = bytearray(js.encode(joint_state(0.0, {"head_pan": 0.1})))
    # After the encapsulation (4), stamp (8) and the empty frame_id (4 + 1, padded to 8): the
    # length of the `name` sequence.
    assert raw[20:24] == (1).to_bytes(4, "little")
    raw[20:24] = (2**30).to_bytes(4, "little")
    with pytest.raises(MessageError, match="does not decode"):
        js.decode(bytes(raw))


def test_encoding_another_type_is_a_message_error(codec: Codec) -> None:
    from gazebot.io.ros2.convert import pose_stamped

    with pytest.raises(MessageError, match="cannot encode"):
        codec.encode(pose_stamped(0.0, np.zeros(3), "world"))
