"""The one error type of the ROS 2 message layer."""

from __future__ import annotations

#: Longest reason kept (characters): a reason may quote wire data, which a sender controls.
MAX_REASON_CHARS = 200


def one_line(text: str, limit: int = MAX_REASON_CHARS) -> str:
    """``text`` on one line, cut to ``limit`` characters (with ``...`` when cut)."""
    flat = " ".join(str(text).split())
    return flat if len(flat) <= limit else flat[: limit - 3] + "..."


class MessageError(ValueError):
    """A ROS 2 message that cannot be used: bytes that do not decode as the type, a value that
    cannot go on the wire (NaN or infinite coordinates, inconsistent arrays), or an unknown type.

    A transport counts and drops these. ``type_name`` is the ROS type (``pkg/msg/Name``),
    ``reason`` one line saying what was wrong (made one line and cut to
    :data:`MAX_REASON_CHARS`: it may quote data a sender chose).
    """

    def __init__(self, type_name: str, reason: str) -> None:
        self.type_name = type_name
        self.reason = one_line(reason)
        super().__init__(f"{type_name}: {self.reason}")
