"""The attachment rmw_zenoh sends with every sample: sequence number, source timestamp and the
publisher's GID, serialized as zenoh-ext does ``(int64, int64, uint8[16])``: two little-endian
int64 and the GID as a LEB128 length (16) followed by its bytes (33 bytes in all)."""

from __future__ import annotations

import struct
from dataclasses import dataclass

import xxhash

GID_SIZE = 16
_HEAD = struct.Struct("<qqB")


class AttachmentError(ValueError):
    """An attachment that is not rmw_zenoh's layout."""


@dataclass(frozen=True)
class Attachment:
    """Attributes: ``sequence_number`` (per publisher, from 1), ``source_timestamp`` (ns since
    the epoch, the publisher's clock), ``gid`` (16 bytes identifying the publisher)."""

    sequence_number: int
    source_timestamp: int
    gid: bytes

    def encode(self) -> bytes:
        if len(self.gid) != GID_SIZE:
            raise ValueError(f"a GID has {GID_SIZE} bytes, got {len(self.gid)}")
        return _HEAD.pack(self.sequence_number, self.source_timestamp, GID_SIZE) + self.gid

    @classmethod
    def decode(cls, raw: bytes) -> Attachment:
        """Parse ``raw``; :class:`AttachmentError` when it is not 33 bytes of that layout."""
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
