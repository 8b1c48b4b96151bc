"""The records of an MCAP file in file order, with bounded cost: every chunk's declared
uncompressed size and compression ratio are checked before it is decompressed, and it is
decompressed to at most its declared size (the ``mcap`` library's own readers allocate whatever
a chunk declares: a 32 kB file declaring a 1 GiB zstd chunk, or an lz4 bomb, runs for minutes
at gigabytes). Used by :mod:`.mcap_file` and :mod:`.mcap_recover`.
"""

from __future__ import annotations

import io
import os
import struct
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any, BinaryIO

from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, Footer, Message, Schema
from mcap.stream_reader import StreamReader

# A chunk declaring less than this is decompressed whatever its ratio: its cost is bounded, and
# a small chunk of repeated messages compresses far beyond any ratio a bomb is refused at.
_RATIO_FLOOR_BYTES = 1024 * 1024
_RECORD_HEAD = struct.Struct("<BQ")  # opcode, length
_PIECE = 1024 * 1024  # bytes decompressed at a time


class ChunkLimitError(ValueError):
    """A chunk over a limit (declared size or compression ratio): hostile or damaged input,
    never read as a recording cut short."""


class DamagedError(ValueError):
    """A record that does not parse (a file cut short ends with one)."""


@dataclass
class McapRecords:
    """What :func:`iter_messages` found: :attr:`finished` (the file ends with its footer),
    the schemas and channels by id, and the number of chunks read."""

    schemas: dict[int, Schema] = field(default_factory=dict)
    channels: dict[int, Channel] = field(default_factory=dict)
    chunks: int = 0
    finished: bool = False


class CappedReads:
    """A binary file whose ``read(n)`` never asks for more than is left in it: the mcap reader
    reads a record's length field and then that many bytes, so one damaged length in a 1 kB
    file would otherwise allocate up to gigabytes before finding the file too short."""

    def __init__(self, f: BinaryIO) -> None:
        self._f = f
        self._size = os.fstat(f.fileno()).st_size

    def read(self, n: int | None = -1) -> bytes:
        """Up to ``n`` bytes, never more than are left in the file (all that is left for ``None``
        or a negative ``n``)."""
        if n is None or n < 0:
            return self._f.read()
        return self._f.read(max(0, min(n, self._size - self._f.tell())))

    def __getattr__(self, name: str) -> Any:  # seek, tell, seekable, ... of the file
        return getattr(self._f, name)


def check_chunk(where: str, declared: int, packed: int, max_bytes: int, max_ratio: float) -> None:
    """Refuse a chunk (named ``where``) declaring ``declared`` bytes uncompressed from ``packed``
    bytes over the limits (see :func:`decompress_chunk`).

    Raises:
        ChunkLimitError: Over a limit.
    """
    if declared > max_bytes:
        raise ChunkLimitError(
            f"{where} declares {declared} bytes uncompressed, over the limit of {max_bytes} "
            "bytes (RecordingLimits.max_chunk_bytes)"
        )
    if declared > _RATIO_FLOOR_BYTES and declared > max_ratio * max(packed, 1):
        raise ChunkLimitError(
            f"{where} declares {declared} bytes from {packed} compressed "
            f"(ratio {declared / max(packed, 1):.0f}), over the limit of {max_ratio:g} "
            "(RecordingLimits.max_chunk_ratio)"
        )


def check_mcap_chunks(f: BinaryIO, max_bytes: int, max_ratio: float) -> None:
    """Check every chunk of the MCAP file ``f`` against the limits without decompressing any
    (for readers that decompress by themselves, as rosbags does); stops quietly where the file
    stops parsing (the reader reports that).

    Raises:
        ChunkLimitError: A chunk over a limit.
    """
    number = 0
    records = StreamReader(CappedReads(f), emit_chunks=True).records  # type: ignore[arg-type]
    try:
        for record in records:
            if isinstance(record, Chunk):
                number += 1
                check_chunk(f"chunk {number}", record.uncompressed_size, len(record.data),
                            max_bytes, max_ratio)
    except ChunkLimitError:
        raise
    except (McapError, struct.error, UnicodeDecodeError, ValueError, KeyError):
        return


def decompress_chunk(
    chunk: Chunk, number: int, max_bytes: int, max_ratio: float
) -> bytes | bytearray:
    """The records of ``chunk`` (the ``number``-th of its file, from 1), uncompressed.

    Raises:
        ChunkLimitError: The chunk declares more than ``max_bytes``, or (declaring over 1 MiB)
            more than ``max_ratio`` times its compressed size.
        DamagedError: An unknown compression, data that does not decompress, or a size other
            than declared.
    """
    declared = chunk.uncompressed_size
    where = f"chunk {number}"
    check_chunk(where, declared, len(chunk.data), max_bytes, max_ratio)
    try:
        # Up to one piece past the declared size (a chunk that lies is caught there),
        # appended to one buffer: the declared size is held once, not twice.
        if chunk.compression == "":
            data: bytes | bytearray = chunk.data
        elif chunk.compression == "zstd":
            import zstandard

            with zstandard.ZstdDecompressor().stream_reader(io.BytesIO(chunk.data)) as r:
                data = _gather(iter(lambda: r.read(_PIECE), b""), declared)
        elif chunk.compression == "lz4":
            data = _gather(_lz4_pieces(chunk.data), declared)
        else:
            raise DamagedError(f"{where}: unknown compression {chunk.compression!r}")
    except DamagedError:
        raise
    except Exception as exc:  # zstandard.ZstdError, RuntimeError of lz4: damaged data
        raise DamagedError(f"{where} does not decompress ({exc})") from None
    if len(data) != declared:
        raise DamagedError(
            f"{where} decompresses to {'more' if len(data) > declared else len(data)} bytes, "
            f"declared {declared}"
        )
    return data


def chunk_records(data: bytes | bytearray, number: int) -> Iterator[Schema | Channel | Message]:
    """The schemas, channels and messages in a chunk's uncompressed ``data`` (other records,
    which the MCAP specification does not put in chunks, are skipped by their length).

    Raises:
        DamagedError: A record cut short or of opcode 0 (reserved: zeros are not records, and
            a chunk of zeros would otherwise be millions of empty records to skip).
    """
    size, pos = len(data), 0
    while pos < size:
        where = f"chunk {number}, byte {pos}"
        if size - pos < _RECORD_HEAD.size:
            raise DamagedError(f"{where}: a record cut short")
        opcode, length = _RECORD_HEAD.unpack_from(data, pos)
        body, pos = pos + _RECORD_HEAD.size, pos + _RECORD_HEAD.size + length
        if opcode == 0:
            raise DamagedError(f"{where}: opcode 0 is not a record")
        if pos > size:
            raise DamagedError(f"{where}: a record of {length} bytes past the chunk's end")
        if opcode not in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE):
            continue
        stream = ReadDataStream(io.BytesIO(data[body:pos]))
        try:
            if opcode == Opcode.SCHEMA:
                yield Schema.read(stream)
            elif opcode == Opcode.CHANNEL:
                yield Channel.read(stream)
            else:
                yield Message.read(stream, length)
        except (McapError, struct.error, UnicodeDecodeError, ValueError) as exc:
            raise DamagedError(f"{where}: {Opcode(opcode).name.lower()} does not parse "
                               f"({exc!r})") from None


def _lz4_pieces(data: bytes) -> Iterator[bytes]:
    """The decompressed lz4 frame ``data``, ``_PIECE`` bytes at a time."""
    import lz4.frame

    lz = lz4.frame.LZ4FrameDecompressor()
    out = lz.decompress(data, max_length=_PIECE)
    while out:
        yield out
        if lz.eof or lz.needs_input:
            return
        out = lz.decompress(b"", max_length=_PIECE)


def _gather(pieces: Iterator[bytes], limit: int) -> bytearray:
    """The ``pieces`` joined, stopping once more than ``limit`` bytes came."""
    out = bytearray()
    for piece in pieces:
        out += piece
        if len(out) > limit:
            break
    return out


def iter_messages(
    f: BinaryIO, found: McapRecords, max_chunk_bytes: int, max_chunk_ratio: float
) -> Iterator[tuple[Schema | None, Channel, Message]]:
    """``(schema, channel, message)`` of every message of the MCAP file ``f``, in file order;
    fills ``found`` as it goes (``finished`` once the footer is read).

    Raises:
        ChunkLimitError: A chunk over a limit (see :func:`decompress_chunk`).
        DamagedError: A record that does not parse: where a file cut short ends, or damage.
    """
    reader = StreamReader(CappedReads(f), emit_chunks=True)  # type: ignore[arg-type]
    try:
        for record in reader.records:
            inner: Iterator[Any]
            if isinstance(record, Chunk):
                found.chunks += 1
                data = decompress_chunk(record, found.chunks, max_chunk_bytes, max_chunk_ratio)
                inner = chunk_records(data, found.chunks)
            else:
                inner = iter([record])
            for rec in inner:
                if isinstance(rec, Schema):
                    found.schemas[rec.id] = rec
                elif isinstance(rec, Channel):
                    found.channels[rec.id] = rec
                elif isinstance(rec, Message):
                    channel = found.channels.get(rec.channel_id)
                    if channel is None:
                        raise DamagedError(f"a message on unknown channel {rec.channel_id}")
                    yield found.schemas.get(channel.schema_id), channel, rec
                elif isinstance(rec, Footer):
                    found.finished = True
    except (ChunkLimitError, DamagedError):
        raise
    except (McapError, struct.error, UnicodeDecodeError, ValueError, KeyError) as exc:
        where = f"after chunk {found.chunks}" if found.chunks else "before the first chunk"
        raise DamagedError(f"a record {where} does not parse ({exc!r})") from None
