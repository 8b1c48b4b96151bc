"""The attachment rmw_zenoh sends with every sample: sequence number, source timestamp and the
publisher's GID, serialized as zenoh-ext does ``(int64, int64, uint8[16])``: two little-endian
int64 and the GID as a LEB128 length (16) followed by its bytes (33 bytes in all).

rmw_zenoh 0.2.0 to 0.2.3 (Jazzy, the first releases on Zenoh 1.0) sent the same three values as
labelled pairs (``sequence_number``, ``source_timestamp``, ``source_gid``, each label and value
a LEB128 length followed by its bytes); :meth:`Attachment.decode` reads that layout too and marks
the result ``legacy`` so the node can warn once that an old rmw_zenoh is on the bus."""

from __future__ import annotations

import struct
from dataclasses import dataclass

import xxhash

GID_SIZE = 16
_HEAD = struct.Struct("<qqB")


class AttachmentError(ValueError):
    """An attachment that is not rmw_zenoh's layout."""


class LegacyAttachmentError(AttachmentError):
    """An attachment labelled as rmw_zenoh 0.2.0-0.2.3 labelled it, whose values do not read."""


_LEGACY_SEQ = b"sequence_number"


@dataclass(frozen=True)
class Attachment:
    """Attributes: ``sequence_number`` (per publisher, from 1), ``source_timestamp`` (ns since
    the epoch, the publisher's clock), ``gid`` (16 bytes identifying the publisher)."""

    sequence_number: int
    source_timestamp: int
    gid: bytes
    legacy: bool = False

    def encode(self) -> bytes:
        """The 33 bytes rmw_zenoh attaches: sequence number, source timestamp, GID length, GID."""
        if len(self.gid) != GID_SIZE:
            raise ValueError(f"a GID has {GID_SIZE} bytes, got {len(self.gid)}")
        return _HEAD.pack(self.sequence_number, self.source_timestamp, GID_SIZE) + self.gid

    @classmethod
    def decode(cls, raw: bytes) -> Attachment:
        """Parse ``raw``; :class:`AttachmentError` when it is neither 33 bytes of that layout
        nor the labelled layout of rmw_zenoh 0.2.0-0.2.3 (:class:`LegacyAttachmentError` when it
        carries those labels but not readable values)."""
        if raw[1:1 + len(_LEGACY_SEQ)] == _LEGACY_SEQ:
            return _decode_labelled(raw)
        if len(raw) != _HEAD.size + GID_SIZE:
            raise AttachmentError(
                f"attachment of {len(raw)} bytes, expected {_HEAD.size + GID_SIZE}")
        seq, stamp, n = _HEAD.unpack_from(raw)
        if n != GID_SIZE:
            raise AttachmentError(f"attachment GID length {n}, expected {GID_SIZE}")
        return cls(seq, stamp, bytes(raw[_HEAD.size:]))


def gid_of(token_key: str) -> bytes:
    """An entity's GID as rmw_zenoh computes it: XXH3-128 of its liveliness token's key
    expression, low 64 bits then high 64 bits, each little-endian."""
    h = xxhash.xxh3_128_intdigest(token_key.encode())
    return (h & (2**64 - 1)).to_bytes(8, "little") + (h >> 64).to_bytes(8, "little")


def _leb128(raw: bytes, at: int) -> tuple[int, int]:
    """The unsigned LEB128 integer at ``raw[at:]`` and the offset after it."""
    value = shift = 0
    while True:
        if at >= len(raw) or shift > 28:
            raise LegacyAttachmentError("labelled attachment: truncated length")
        byte = raw[at]
        at += 1
        value |= (byte & 0x7F) << shift
        shift += 7
        if not byte & 0x80:
            return value, at


def _decode_labelled(raw: bytes) -> Attachment:
    """The labelled pairs of rmw_zenoh 0.2.0-0.2.3, marked ``legacy``."""
    fields: dict[bytes, bytes] = {}
    at = 0
    while at < len(raw):
        items = []
        for _ in range(2):
            n, at = _leb128(raw, at)
            if at + n > len(raw):
                raise LegacyAttachmentError("labelled attachment: truncated value")
            items.append(bytes(raw[at:at + n]))
            at += n
        fields[items[0]] = items[1]
    seq, stamp = fields.get(_LEGACY_SEQ, b""), fields.get(b"source_timestamp", b"")
    gid = fields.get(b"source_gid", b"")
    if len(seq) != 8 or len(stamp) != 8 or len(gid) != GID_SIZE:
        raise LegacyAttachmentError(
            "labelled attachment: expected 8-byte sequence_number and source_timestamp and a "
            f"{GID_SIZE}-byte source_gid")
    return Attachment(int.from_bytes(seq, "little", signed=True),
                      int.from_bytes(stamp, "little", signed=True), gid, legacy=True)
