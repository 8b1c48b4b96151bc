"""CDR bytes <-> ROS 2 messages of one type, as rmw_zenoh puts them on the wire.

A payload is the XCDR1 encapsulation header (``00 01 00 00``: little-endian CDR) followed by the
message in CDR, serialized by rosbags. Anything that does not decode as the type (garbage, a
truncated message, an oversized one) raises :class:`~gazebot.io.ros2.errors.MessageError`.
"""

from __future__ import annotations

from dataclasses import dataclass

from rosbags.typesys.store import Typestore

from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.names import TypeInfo, type_info

#: Largest payload decoded by default (bytes): a 1024x600 JPEG eye frame is well under this.
MAX_PAYLOAD_BYTES = 4 * 1024 * 1024

# The two CDR (XCDR1) encapsulation kinds ROS 2 uses: big- and little-endian plain CDR.
_ENCAPSULATIONS = (b"\x00\x00", b"\x00\x01")


@dataclass(frozen=True)
class Codec:
    """Serializes and deserializes messages of one ROS 2 type.

    Attributes:
        store: The type system (see :func:`gazebot.io.ros2.typestore.typestore`).
        info: The type's ROS name, DDS name and RIHS01 hash.
        max_bytes: Payloads longer than this are refused unread.
    """

    store: Typestore
    info: TypeInfo
    max_bytes: int = MAX_PAYLOAD_BYTES

    @classmethod
    def for_type(
        cls, store: Typestore, type_name: str, max_bytes: int = MAX_PAYLOAD_BYTES
    ) -> Codec:
        """The codec of ``type_name`` (``pkg/msg/Name``); :class:`MessageError` if unknown."""
        return cls(store, type_info(store, type_name), max_bytes)

    @property
    def type_name(self) -> str:
        """The type's ROS name, ``pkg/msg/Name``."""
        return self.info.name

    def encode(self, msg: object) -> bytes:
        """CDR bytes (little-endian, with the encapsulation header) of ``msg``.

        Raises:
            MessageError: ``msg`` is not a message of this type or a field has the wrong type.
        """
        got = getattr(msg, "__msgtype__", type(msg).__name__)
        if got != self.info.name:
            raise MessageError(self.info.name, f"cannot encode a {got}")
        try:
            return bytes(self.store.serialize_cdr(msg, self.info.name))
        except Exception as exc:  # rosbags raises struct/attribute/serde errors alike
            raise MessageError(self.info.name, f"does not serialize ({exc})") from None

    def decode(self, raw: bytes | bytearray | memoryview) -> object:
        """The message in ``raw`` CDR bytes.

        Raises:
            MessageError: Oversized, no CDR encapsulation header, truncated or otherwise not a
                message of this type.
        """
        data = bytes(raw)
        if len(data) > self.max_bytes:
            raise MessageError(
                self.info.name, f"oversized: {len(data)} bytes, at most {self.max_bytes}"
            )
        if len(data) < 4 or data[:2] not in _ENCAPSULATIONS:
            raise MessageError(self.info.name, "not CDR: no XCDR1 encapsulation header")
        try:
            return self.store.deserialize_cdr(data, self.info.name)
        except Exception as exc:  # SerdeError, UnicodeDecodeError, ... from rosbags
            raise MessageError(self.info.name, f"does not decode ({exc})") from None
