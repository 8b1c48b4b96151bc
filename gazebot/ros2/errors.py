"""The one error type of the ROS 2 message layer."""

from __future__ import annotations


class MessageError(ValueError):
    """A ROS 2 message that cannot be used: bytes that do not decode as the type, a value that
    cannot go on the wire (NaN or infinite coordinates, inconsistent arrays), or an unknown type.

    A transport counts and drops these. ``type_name`` is the ROS type (``pkg/msg/Name``),
    ``reason`` one line saying what was wrong.
    """

    def __init__(self, type_name: str, reason: str) -> None:
        self.type_name = type_name
        self.reason = reason
        super().__init__(f"{type_name}: {reason}")
