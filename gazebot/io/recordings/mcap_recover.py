"""``recover``: rewrite an MCAP file that a killed recorder left without its summary (or with a
damaged tail) as a finished one, with the semantics of the MCAP CLI's ``mcap recover``: every
complete chunk and message up to the first record that does not parse is copied, with the
schemas and channels they use, into a new file with index and summary that every reader opens
(the ``mcap`` library's default reader seeks the summary and refuses a file without it).
Attachments and metadata are not copied (gazebot's recorders write none). Chunks are read with
the bounds of :mod:`.mcap_records`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from gazebot.io.atomic import atomic_path
from gazebot.io.recordings.base import RecordingError, RecordingLimits
from gazebot.io.recordings.mcap_records import (
    CappedReads,
    ChunkLimitError,
    DamagedError,
    McapRecords,
    iter_messages,
)

log = logging.getLogger("gazebot.io.recordings")


@dataclass(frozen=True)
class Recovered:
    """What :func:`recover_mcap` wrote.

    Attributes:
        path: The recovered file.
        messages: Messages copied.
        chunks: Chunks read from the damaged file.
        last_log_time_ns: Log time of the last message copied (``None``: none).
        problem: Why reading stopped before the footer (``None``: the file was finished).
    """

    path: Path
    messages: int
    chunks: int
    last_log_time_ns: int | None
    problem: str | None


def recovered_path(path: Path) -> Path:
    """The default output of recovering ``path``: ``NAME-recovered.mcap`` beside it."""
    return path.with_name(f"{path.stem}-recovered{path.suffix}")


def recover_mcap(
    path: str | Path, out: str | Path | None = None, limits: RecordingLimits | None = None
) -> Recovered:
    """Copy every complete message of the MCAP file ``path`` to ``out`` (default:
    :func:`recovered_path`), finished with index and summary; ``out`` is written atomically
    and may not be ``path``.

    Raises:
        RecordingError: Not an MCAP file, a chunk over a limit, or ``out`` is ``path``.
    """
    path = Path(path)
    out = recovered_path(path) if out is None else Path(out)
    if out.resolve() == path.resolve():
        raise RecordingError(path, "the recovered file must be another file (--out)")
    limits = limits or RecordingLimits()
    found = McapRecords()
    count, last, problem = 0, None, None
    try:
        with open(path, "rb") as raw, atomic_path(out) as tmp, open(tmp, "wb") as dst:
            header = make_reader(CappedReads(raw)).get_header()  # type: ignore[arg-type]
            raw.seek(0)
            writer = Writer(dst, compression=CompressionType.ZSTD)
            writer.start(profile=header.profile, library=header.library)
            schema_ids: dict[int, int] = {}
            channel_ids: dict[int, int] = {}
            try:
                for schema, channel, message in iter_messages(
                    raw, found, limits.max_chunk_bytes, limits.max_chunk_ratio
                ):
                    if schema is not None and schema.id not in schema_ids:
                        schema_ids[schema.id] = writer.register_schema(
                            schema.name, schema.encoding, schema.data
                        )
                    if channel.id not in channel_ids:
                        channel_ids[channel.id] = writer.register_channel(
                            channel.topic, channel.message_encoding,
                            schema_ids.get(channel.schema_id, 0), dict(channel.metadata),
                        )
                    writer.add_message(
                        channel_ids[channel.id], message.log_time, message.data,
                        message.publish_time, message.sequence,
                    )
                    count, last = count + 1, message.log_time
            except DamagedError as exc:
                problem = str(exc)
            writer.finish()
    except ChunkLimitError as exc:
        raise RecordingError(path, f"refused: {exc}") from None
    except RecordingError:
        raise
    except FileNotFoundError:
        raise RecordingError(path, "no such file") from None
    except Exception as exc:  # mcap's McapError (bad magic, ...), struct.error: not MCAP
        raise RecordingError(path, f"not an MCAP file ({exc!r})") from None
    if problem is None and not found.finished:
        problem = "the file ends without its footer"
    if problem is not None:
        log.info("%s: read up to the first damaged record: %s", path, problem)
    return Recovered(out, count, found.chunks, last, problem)
