"""Element counts of a CDR message read before it is decoded (issue 30).

The size cap of a topic bounds the bytes, not the work: a 56 kB ``JointState`` with 7000 empty
names is under the cap, and decoding it takes milliseconds of the interpreter (a stream of them
stalls the engine). The first sequence of a message is read from its CDR prefix (the
encapsulation header, the ``std_msgs/Header`` when the message starts with one, then the
sequence's ``uint32`` length), so a message with more elements than a topic needs is dropped
without being decoded.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from gazebot.io.ros2.errors import MessageError

#: Most joints a ``JointState`` or ``JointTrajectory`` may name (a dual-arm humanoid has ~60).
MAX_JOINTS = 256
#: Most transforms of one ``TFMessage`` gazebot reads (a full human skeleton has ~100 frames).
MAX_TRANSFORMS = 256
#: Most points of one ``JointTrajectory`` (gazebot streams one; a planned path has hundreds).
MAX_POINTS = 1024

_ENCAPSULATION = 4  # bytes: representation id, options


@dataclass(frozen=True)
class _Reader:
    data: bytes
    little: bool

    def u32(self, pos: int) -> tuple[int, int]:
        """The ``uint32`` at ``pos`` (aligned to 4 from the start of the body) and the
        position after it."""
        pos += (-(pos - _ENCAPSULATION)) % 4
        if pos + 4 > len(self.data):
            raise ValueError("message ends inside a length")
        return struct.unpack_from("<I" if self.little else ">I", self.data, pos)[0], pos + 4

    def string_end(self, pos: int) -> int:
        n, pos = self.u32(pos)
        if pos + n > len(self.data):
            raise ValueError("message ends inside a string")
        return pos + n


def _reader(data: bytes) -> _Reader:
    if len(data) < _ENCAPSULATION:
        raise ValueError("message shorter than its CDR encapsulation header")
    return _Reader(data, little=data[1] & 1 == 1)


def _after_header(r: _Reader) -> int:
    """The position after a leading ``std_msgs/Header`` (stamp: two 32-bit ints, frame id)."""
    return r.string_end(_ENCAPSULATION + 8)


def first_sequence_length(data: bytes, *, header: bool) -> int:
    """The length of the message's first field, a sequence (after a leading
    ``std_msgs/Header`` when ``header``); ``ValueError`` when the bytes end before it."""
    r = _reader(data)
    pos = _after_header(r) if header else _ENCAPSULATION
    return r.u32(pos)[0]


def check_count(what: str, field: str, n: int, most: int) -> None:
    """:class:`MessageError` naming the message type and field when ``n`` exceeds ``most``."""
    if n > most:
        raise MessageError(what, f"{n} elements in {field}, at most {most} are read "
                           "(dropped before decoding)")


def check_joint_state(data: bytes, what: str = "sensor_msgs/msg/JointState") -> None:
    """Drop a ``JointState`` naming more than :data:`MAX_JOINTS` joints."""
    check_count(what, "name", _length(what, data, header=True), MAX_JOINTS)


def check_tf(data: bytes, what: str = "tf2_msgs/msg/TFMessage") -> None:
    """Drop a ``TFMessage`` of more than :data:`MAX_TRANSFORMS` transforms."""
    check_count(what, "transforms", _length(what, data, header=False), MAX_TRANSFORMS)


def check_trajectory(data: bytes, what: str = "trajectory_msgs/msg/JointTrajectory") -> None:
    """Drop a ``JointTrajectory`` naming more than :data:`MAX_JOINTS` joints or with more
    than :data:`MAX_POINTS` points."""
    try:
        r = _reader(data)
        n, pos = r.u32(_after_header(r))
        check_count(what, "joint_names", n, MAX_JOINTS)
        for _ in range(n):
            pos = r.string_end(pos)
        points = r.u32(pos)[0]
    except ValueError as exc:
        raise MessageError(what, f"malformed CDR: {exc}") from None
    check_count(what, "points", points, MAX_POINTS)


def _length(what: str, data: bytes, *, header: bool) -> int:
    try:
        return first_sequence_length(data, header=header)
    except ValueError as exc:
        raise MessageError(what, f"malformed CDR: {exc}") from None
