"""MCAP chunks are read with bounded cost: a chunk declaring more than
``RecordingLimits.max_chunk_bytes`` or a compression ratio over ``max_chunk_ratio`` is refused
before it is decompressed, a chunk is never decompressed past its declared size, and each case
is one line naming the file, the chunk and the limit; the same for ``gazebot mcap recover``.
The CSV header's duplicate-column check is linear."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gazebot.apps.cli import main
from gazebot.io.recordings import RecordingError, RecordingLimits, load_recording
from gazebot.io.recordings.mcap_recover import recover_mcap

MiB = 1024 * 1024


def _zeros_compressed(compression: str, size: int) -> bytes:
    """``size`` zero bytes compressed, made piecewise (the test itself stays small)."""
    piece = b"\0" * min(size, MiB)
    pieces = [len(piece)] * (size // MiB) + ([size % MiB] if size % MiB else [])
    if size < MiB:
        pieces = [size]
    if compression == "zstd":
        import zstandard

        z = zstandard.ZstdCompressor().compressobj()
        return b"".join([z.compress(piece[:n]) for n in pieces] + [z.flush()])
    if compression == "lz4":
        import lz4.frame

        c = lz4.frame.LZ4FrameCompressor()
        return b"".join([c.begin()] + [c.compress(piece[:n]) for n in pieces] + [c.flush()])
    return b"\0" * size


def _mcap_with_chunk(path: Path, compression: str, data: bytes, declared: int) -> Path:
    """A finished MCAP file (header, one chunk, data end, footer) whose chunk holds ``data``
    and declares ``declared`` bytes uncompressed."""
    from mcap.data_stream import RecordBuilder
    from mcap.records import Chunk, DataEnd, Footer, Header
    from mcap.writer import MCAP0_MAGIC

    b = RecordBuilder()
    b.write(MCAP0_MAGIC)
    Header("ros2", "test").write(b)
    Chunk(compression="" if compression == "none" else compression, data=data,
          message_start_time=0, message_end_time=0, uncompressed_crc=0,
          uncompressed_size=declared).write(b)
    DataEnd(0).write(b)
    Footer(0, 0, 0).write(b)
    b.write(MCAP0_MAGIC)
    path.write_bytes(b.end())
    return path


def _one_line_error(path: Path, match: str) -> str:
    with pytest.raises(RecordingError) as info:
        load_recording(path)
    text = str(info.value)
    assert text.startswith(str(path)) and "\n" not in text
    assert match in text, text
    return text


def test_a_32_kB_file_declaring_a_1_GiB_chunk_is_refused_naming_chunk_and_limit(
        tmp_path, bounded_memory):
    f = _mcap_with_chunk(tmp_path / "gib.mcap", "zstd", _zeros_compressed("zstd", 4 * MiB),
                         1024 * MiB)
    with bounded_memory(10e6):
        text = _one_line_error(f, "chunk 1 declares 1073741824 bytes")
    assert "RecordingLimits.max_chunk_bytes" in text and str(32 * MiB) in text


def test_a_zstd_bomb_under_the_size_limit_is_refused_by_its_ratio(tmp_path, bounded_memory):
    data = _zeros_compressed("zstd", 30 * MiB)
    f = _mcap_with_chunk(tmp_path / "bomb.mcap", "zstd", data, 30 * MiB)
    with bounded_memory(10e6):
        _one_line_error(f, "RecordingLimits.max_chunk_ratio")
    # Allowed a higher ratio, it is decompressed (30 MiB, within the bound): zeros are no records.
    limits = RecordingLimits(max_chunk_ratio=1e9)
    with bounded_memory(100e6), pytest.raises(RecordingError, match="opcode 0 is not a record"):
        load_recording(f, limits=limits)


def test_an_lz4_bomb_is_refused_and_one_that_lies_is_cut_at_its_declared_size(
        tmp_path, bounded_memory):
    data = _zeros_compressed("lz4", 300 * MiB)  # ~1.2 MB, as the 1.1 MB bomb
    honest = _mcap_with_chunk(tmp_path / "honest.mcap", "lz4", data, 300 * MiB)
    with bounded_memory(10e6):
        _one_line_error(honest, "over the limit of")
    liar = _mcap_with_chunk(tmp_path / "liar.mcap", "lz4", data, MiB)
    with bounded_memory(20e6):
        _one_line_error(liar, "chunk 1 decompresses to more bytes, declared 1048576")


def test_recover_refuses_a_bomb_in_one_line(tmp_path, capsys):
    f = _mcap_with_chunk(tmp_path / "gib.mcap", "zstd", _zeros_compressed("zstd", MiB),
                         1024 * MiB)
    with pytest.raises(RecordingError, match="chunk 1 declares"):
        recover_mcap(f)
    assert main(["mcap", "recover", str(f)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "gib.mcap" in err and "max_chunk_bytes" in err
    assert not (tmp_path / "gib-recovered.mcap").exists()


@pytest.mark.timeout(300)
@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(
    compression=st.sampled_from(["zstd", "lz4", "none"]),
    size=st.integers(0, 8 * MiB),
    declared=st.one_of(st.sampled_from(["true", "less", "more"]),
                       st.integers(0, 2**64 - 1)),
)
def test_any_declared_size_of_any_chunk_reads_or_fails_in_one_line_in_bounded_memory(
        tmp_path_factory, bounded_memory, compression, size, declared):
    data = _zeros_compressed(compression, size)
    n = {"true": size, "less": max(0, size - 1), "more": size + 1}.get(declared, declared)
    f = _mcap_with_chunk(tmp_path_factory.mktemp("chunk") / "c.mcap", compression, data, n)
    # The declared cap (32 MiB) and the output bound: never more than the cap decompressed.
    with bounded_memory(100e6):
        for read in (load_recording, recover_mcap):
            try:
                read(f)
            except RecordingError as exc:
                assert str(exc).startswith(str(f)) and "\n" not in str(exc)


def test_a_csv_header_of_200k_columns_is_checked_for_duplicates_linearly(tmp_path,
                                                                        bounded_memory):
    cols = ["t"] + [f"c{i}" for i in range(200_000)] + ["c7"]
    f = tmp_path / "wide.csv"
    f.write_text(",".join(cols) + "\n")
    with bounded_memory(200e6), pytest.raises(RecordingError) as info:
        load_recording(f)
    assert str(info.value) == f"{f}: line 1, column 'c7': duplicate column"


def _bag1_with_chunk(path: Path, data: bytes, declared: int, compression: bytes = b"bz2"):
    """A ROS 1 bag (format 2.0) whose first record is a chunk of ``data`` declaring
    ``declared`` bytes uncompressed."""
    import struct

    def field(name: bytes, value: bytes) -> bytes:
        return struct.pack("<I", len(name) + 1 + len(value)) + name + b"=" + value

    header = (field(b"op", b"\x05") + field(b"compression", compression)
              + field(b"size", struct.pack("<I", declared)))
    path.write_bytes(b"#ROSBAG V2.0\n" + struct.pack("<I", len(header)) + header
                     + struct.pack("<I", len(data)) + data)
    return path


def test_bag_readers_check_chunks_before_rosbags_decompresses_them(tmp_path, bounded_memory):
    import bz2

    from gazebot.io.recordings.rosbag import read_bag

    bomb = bz2.compress(b"\0" * (8 * MiB))  # ~50 bytes declaring 8 MiB
    ros1 = _bag1_with_chunk(tmp_path / "bomb.bag", bomb, 8 * MiB)
    with bounded_memory(10e6):
        _one_line_error(ros1, "chunk 1 declares 8388608 bytes from")
    huge = _bag1_with_chunk(tmp_path / "huge.bag", bomb, 2**32 - 1)
    with bounded_memory(10e6):
        _one_line_error(huge, "RecordingLimits.max_chunk_bytes")
    ros2 = _mcap_with_chunk(tmp_path / "gib.mcap", "zstd", _zeros_compressed("zstd", MiB),
                            1024 * MiB)
    with bounded_memory(10e6), pytest.raises(RecordingError, match="refused: chunk 1 declares"):
        read_bag(ros2)
