"""Record ROS 2 messages to MCAP the way rosbag2 does, for Foxglove, PlotJuggler, ``ros2 bag``
and rosbags to read.

Profile ``ros2``; one schema per message type (name ``pkg/msg/Name``, encoding ``ros2msg``,
the full definition with its dependencies as ``ros2 bag record`` embeds it); one channel per
topic with CDR messages. Log and publish times are the messages' time on the robot's clock
(simulation time in the simulator), in ns. The file is written beside its final name and
renamed into place on a clean close: a failed run leaves no file behind.
"""

from __future__ import annotations

import math
from pathlib import Path

from mcap.writer import CompressionType, Writer
from rosbags.typesys.store import Typestore

from gazebot.io.atomic import AtomicWriter
from gazebot.io.ros2.codec import Codec
from gazebot.io.ros2.errors import MessageError
from gazebot.io.ros2.typestore import typestore

LIBRARY = "gazebot"


class McapRecorder(AtomicWriter):
    """Writes messages of any registered type to one MCAP file.

    Args:
        path: The ``.mcap`` file to write.
        store: The type system (default: the shipped one).
        compression: ``zstd`` (rosbag2's default for MCAP), ``lz4`` or ``none``.
        chunk_size: Bytes of messages per (compressed) chunk.
    """

    def __init__(
        self,
        path: str | Path,
        store: Typestore | None = None,
        compression: str = "zstd",
        chunk_size: int = 1024 * 1024,
    ) -> None:
        kinds = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4,
                 "none": CompressionType.NONE}
        if compression not in kinds:
            raise ValueError(f"compression must be one of {', '.join(kinds)}, not {compression!r}")
        super().__init__(path)
        self.store = typestore() if store is None else store
        self._file = open(self.part, "wb")  # noqa: SIM115 - closed in close()/abort()
        self._writer = Writer(self._file, chunk_size=chunk_size, compression=kinds[compression])
        self._writer.start(profile="ros2", library=LIBRARY)
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, tuple[int, Codec]] = {}
        self._sequence: dict[str, int] = {}
        self.messages = 0

    def _channel(self, topic: str, type_name: str) -> tuple[int, Codec]:
        known = self._channels.get(topic)
        if known is not None:
            if known[1].type_name != type_name:
                raise MessageError(
                    type_name, f"topic {topic} is recorded as {known[1].type_name} already"
                )
            return known
        if type_name not in self._schemas:
            definition, _ = self.store.generate_msgdef(type_name, ros_version=2)
            self._schemas[type_name] = self._writer.register_schema(
                name=type_name, encoding="ros2msg", data=definition.encode()
            )
        codec = Codec.for_type(self.store, type_name)
        channel = self._writer.register_channel(
            topic=topic, message_encoding="cdr", schema_id=self._schemas[type_name]
        )
        self._channels[topic] = (channel, codec)
        return channel, codec

    def write(self, topic: str, msg: object, t: float) -> None:
        """Record ``msg`` on ``topic`` (fully qualified, e.g. ``/gazebot/gaze_target``) at
        ``t`` (s, the robot's clock).

        Raises:
            MessageError: ``t`` is not finite, ``msg`` does not serialize, or ``topic`` was
                recorded with another type.
        """
        type_name = getattr(msg, "__msgtype__", type(msg).__name__)
        _, codec = self._channel(topic, type_name)
        self._add(topic, type_name, codec.encode(msg), t)

    def write_cdr(self, topic: str, type_name: str, data: bytes, t: float) -> None:
        """Record CDR bytes received for ``topic`` as they are (what a bus recorder does, as
        ``ros2 bag record`` stores what it receives): no re-encoding, but they must decode as
        ``type_name``.

        Raises:
            MessageError: An unknown type, bytes that do not decode, a bad ``t``, or a topic
                recorded with another type.
        """
        _, codec = self._channel(topic, type_name)
        codec.decode(data)
        self._add(topic, type_name, bytes(data), t)

    def _add(self, topic: str, type_name: str, data: bytes, t: float) -> None:
        if not math.isfinite(t) or t < 0:
            raise MessageError(type_name, f"log time must be finite and >= 0 s, got {t}")
        channel, _ = self._channels[topic]
        ns = round(t * 1e9)
        seq = self._sequence.get(topic, 0) + 1
        self._sequence[topic] = seq
        self._writer.add_message(
            channel_id=channel, log_time=ns, data=data, publish_time=ns, sequence=seq
        )
        self.messages += 1

    @property
    def topics(self) -> dict[str, str]:
        """Topic -> type of everything recorded so far."""
        return {topic: codec.type_name for topic, (_, codec) in self._channels.items()}

    def close(self) -> Path:
        """Finish the file (summary and index) and move it into place; returns its path."""
        if self._file.closed:
            return self.path
        self._writer.finish()
        self._file.close()
        return self._commit()

    def abort(self) -> None:
        """Drop the partial file."""
        if not self._file.closed:
            self._file.close()
        self.part.unlink(missing_ok=True)
