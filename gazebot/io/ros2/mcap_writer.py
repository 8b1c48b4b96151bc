"""Record ROS 2 messages to MCAP the way rosbag2 does, for Foxglove, PlotJuggler, ``ros2 bag``
and rosbags to read.

Profile ``ros2``; one schema per message type (name ``pkg/msg/Name``, encoding ``ros2msg``,
the full definition with its dependencies as ``ros2 bag record`` embeds it); one channel per
topic with CDR messages. Log and publish times are the times the caller gives, in ns (the bus
recorder and the demo give the wall clock, as rosbag2 does; simulation time stays in the
messages' header stamps).

The file is written under its final name from the start, in chunks: a chunk is written and the
file flushed once ``flush_period`` has passed since the last flush (as rosbag2's MCAP storage
does with its ``chunk_size``), or once the chunk holds ``chunk_size`` bytes. A process killed
at any moment leaves a file whose complete chunks the ``mcap`` stream reader reads (at most
about ``flush_period`` of messages lost); ``gazebot mcap recover`` rewrites it with its index
and summary. With a :class:`Split` the recording goes to ``NAME_0.mcap``, ``NAME_1.mcap``, ...
(rosbag2's ``--max-bag-size`` / ``--max-bag-duration``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from mcap.writer import CompressionType, Writer
from rosbags.typesys.store import Typestore

from gazebot.io.atomic import FinishOrAbort
from gazebot.io.ros2.codec import Codec
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.typestore import typestore

LIBRARY = "gazebot"
FLUSH_PERIOD_S = 1.0
_KINDS = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4, "none": CompressionType.NONE}


@dataclass(frozen=True)
class Split:
    """When a recording moves on to its next file (``None``: no limit); rosbag2's
    ``--max-bag-size`` and ``--max-bag-duration``.

    Attributes:
        max_bytes: A file is closed once it holds at least this many bytes (a file may exceed
            it by one chunk: the size is checked as chunks are written).
        max_duration_s: A file is closed before a message whose log time is this many seconds
            or more after the file's first message.
    """

    max_bytes: int | None = None
    max_duration_s: float | None = None

    def __post_init__(self) -> None:
        if self.max_bytes is not None and self.max_bytes < 1:
            raise ValueError(f"the maximum file size must be >= 1 byte, got {self.max_bytes}")
        d = self.max_duration_s
        if d is not None and not (math.isfinite(d) and d > 0):
            raise ValueError(f"the maximum file duration must be a finite number > 0 s, got {d}")

    @property
    def splits(self) -> bool:
        """Whether any limit is set."""
        return self.max_bytes is not None or self.max_duration_s is not None


def split_path(path: Path, index: int) -> Path:
    """File ``index`` of a split recording named ``path``: ``NAME_<index>.mcap`` (rosbag2's)."""
    return path.with_name(f"{path.stem}_{index}{path.suffix}")


class McapRecorder(FinishOrAbort):
    """Writes messages of any registered type to one MCAP file (or a split series of them).

    Args:
        path: The ``.mcap`` file to write (with a splitting ``split``: the series' name).
        store: The type system (default: the shipped one).
        compression: ``zstd`` (rosbag2's default for MCAP), ``lz4`` or ``none``.
        chunk_size: Bytes of messages per (compressed) chunk at most, before the chunk is
            written.
        flush_period: Seconds (of ``clock``) after which the chunk in progress is written and
            the file flushed: what a killed process loses at most.
        split: When to go on to the next file (default: never).
        clock: The clock of ``flush_period`` (monotonic seconds).

    Raises:
        ValueError: An unknown compression or a ``flush_period`` that is not > 0.
        OSError: The file cannot be created.
    """

    def __init__(
        self,
        path: str | Path,
        store: Typestore | None = None,
        compression: str = "zstd",
        chunk_size: int = 1024 * 1024,
        flush_period: float = FLUSH_PERIOD_S,
        split: Split | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if compression not in _KINDS:
            raise ValueError(f"compression must be one of {', '.join(_KINDS)}, not {compression!r}")
        if not (math.isfinite(flush_period) and flush_period > 0):
            raise ValueError(f"flush_period must be a finite number > 0 s, got {flush_period}")
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.store = typestore() if store is None else store
        self.compression = _KINDS[compression]
        self.chunk_size = chunk_size
        self.flush_period = flush_period
        self.split = split or Split()
        self._clock = clock
        self.files: list[Path] = []
        self._codecs: dict[str, Codec] = {}  # topic -> its type, over every file
        self._sequence: dict[str, int] = {}
        self.messages = 0
        self._open_next()

    def _open_next(self) -> None:
        """Start the next file: header, and schemas and channels as topics reappear."""
        path = split_path(self.path, len(self.files)) if self.split.splits else self.path
        self._file: BinaryIO = open(path, "wb")  # noqa: SIM115 - closed in close()/abort()
        self.files.append(path)
        self._writer = Writer(self._file, chunk_size=self.chunk_size, compression=self.compression)
        self._writer.start(profile="ros2", library=LIBRARY)
        self._file.flush()  # a file killed before its first chunk is an (empty) MCAP file
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._first_ns: int | None = None
        self._flushed_at = self._clock()

    def _codec(self, topic: str, type_name: str) -> Codec:
        known = self._codecs.get(topic)
        if known is not None:
            if known.type_name != type_name:
                raise MessageError(
                    type_name, f"topic {topic} is recorded as {known.type_name} already"
                )
            return known
        codec = Codec.for_type(self.store, type_name)  # raises for an unknown type
        self._codecs[topic] = codec
        return codec

    def _channel(self, topic: str, type_name: str) -> int:
        """The channel of ``topic`` in the current file, registered on first use."""
        if topic in self._channels:
            return self._channels[topic]
        if type_name not in self._schemas:
            definition, _ = self.store.generate_msgdef(type_name, ros_version=2)
            self._schemas[type_name] = self._writer.register_schema(
                name=type_name, encoding="ros2msg", data=definition.encode()
            )
        channel = self._writer.register_channel(
            topic=topic, message_encoding="cdr", schema_id=self._schemas[type_name]
        )
        self._channels[topic] = channel
        return channel

    def write(self, topic: str, msg: object, t: float) -> None:
        """Record ``msg`` on ``topic`` (fully qualified, e.g. ``/gazebot/gaze_target``) with log
        time ``t`` (s).

        Raises:
            MessageError: ``t`` is not finite, ``msg`` does not serialize, or ``topic`` was
                recorded with another type.
        """
        type_name = getattr(msg, "__msgtype__", type(msg).__name__)
        codec = self._codec(topic, type_name)
        self._add(topic, type_name, codec.encode(msg), t)

    def write_cdr(self, topic: str, type_name: str, data: bytes, t: float) -> None:
        """Record CDR bytes received for ``topic`` as they are (what a bus recorder does, as
        ``ros2 bag record`` stores what it receives): no re-encoding, but they must decode as
        ``type_name``.

        Raises:
            MessageError: An unknown type, bytes that do not decode, a bad ``t``, or a topic
                recorded with another type.
        """
        self._codec(topic, type_name).decode(data)
        self._add(topic, type_name, data, t)

    def _add(self, topic: str, type_name: str, data: bytes, t: float) -> None:
        if not math.isfinite(t) or t < 0:
            raise MessageError(type_name, f"log time must be finite and >= 0 s, got {t}")
        if self._file.closed:
            raise MessageError(type_name, f"the recording {self.path} is closed")
        ns = round(t * 1e9)
        if self._full(ns):
            self._finish_file()
            self._open_next()
        if self._first_ns is None:
            self._first_ns = ns
        channel = self._channel(topic, type_name)
        seq = self._sequence.get(topic, 0) + 1
        self._sequence[topic] = seq
        self._writer.add_message(
            channel_id=channel, log_time=ns, data=data, publish_time=ns, sequence=seq
        )
        self.messages += 1
        self.flush_if_due()

    def _full(self, ns: int) -> bool:
        """Whether the current file is done before a message at ``ns``."""
        if self._first_ns is None:
            return False  # every file holds at least one message
        s = self.split
        if s.max_bytes is not None and self._file.tell() >= s.max_bytes:
            return True
        return s.max_duration_s is not None and (ns - self._first_ns) >= s.max_duration_s * 1e9

    def flush_if_due(self) -> None:
        """:meth:`flush` if ``flush_period`` has passed since the last flush."""
        if self._clock() - self._flushed_at >= self.flush_period:
            self.flush()

    def flush(self) -> None:
        """Write the chunk in progress (if it holds a message) and flush the file to the
        operating system: a process killed after this loses nothing recorded before it."""
        if self._file.closed:
            return
        self._writer.flush()
        self._flushed_at = self._clock()

    @property
    def topics(self) -> dict[str, str]:
        """Topic -> type of everything recorded so far."""
        return {topic: codec.type_name for topic, codec in self._codecs.items()}

    def _finish_file(self) -> None:
        self._writer.finish()
        self._file.close()

    def close(self) -> Path:
        """Finish the file (summary and index); returns its path (of a split recording: the
        last file's, all of them in :attr:`files`)."""
        if not self._file.closed:
            self._finish_file()
        return self.files[-1]

    def abort(self) -> None:
        """Stop and delete what was written (a failed run that must leave no file)."""
        if not self._file.closed:
            self._file.close()
        for path in self.files:
            path.unlink(missing_ok=True)

