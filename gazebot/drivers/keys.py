"""The Zenoh key layout of one robot: every topic lives under ``gazebot/<robot id>/``.

========================================  =============================  ==========================
key                                       payload (``payloads.py``)      published by
========================================  =============================  ==========================
``gazebot/<id>/tracking``                 :class:`TrackingMsg`           robot / tracker, 120 Hz
``gazebot/<id>/joint_states``             :class:`JointStateMsg`         robot
``gazebot/<id>/head/command``             :class:`HeadCommandMsg`        engine
``gazebot/<id>/eyes``                     :class:`EyeStateMsg`           engine
``gazebot/<id>/eyes/frame``               :class:`EyeFrameMsg`           engine, while subscribed
``gazebot/<id>/arm/command``              :class:`ArmCommandMsg`         anyone (operator, planner)
``gazebot/<id>/events``                   :class:`EventMsg`              engine (phase, behavior,
                                                                         fault), robot (robot_*)
``gazebot/<id>/events/history/<node>``    queryable -> :class:`EventHistoryMsg`   every node
``gazebot/<id>/status``                   :class:`StatusMsg`             every node, heartbeat
``gazebot/<id>/alive/<node>``             liveliness token (no payload)  every node
========================================  =============================  ==========================
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_CHUNK = re.compile(r"^[A-Za-z0-9_-]+$")


def check_chunk(value: str, what: str) -> str:
    """Return ``value`` if it is one key chunk (letters, digits, ``_``, ``-``), else raise."""
    if not isinstance(value, str) or not _CHUNK.match(value):
        raise ValueError(
            f"{what} must be letters, digits, '_' or '-' (one Zenoh key chunk), got {value!r}"
        )
    return value


@dataclass(frozen=True)
class KeyLayout:
    """Key expressions for robot ``robot_id`` (default ``sim``) under ``prefix``."""

    robot_id: str = "sim"
    prefix: str = "gazebot"

    def __post_init__(self) -> None:
        check_chunk(self.robot_id, "robot id")
        check_chunk(self.prefix, "key prefix")

    @property
    def root(self) -> str:
        return f"{self.prefix}/{self.robot_id}"

    @property
    def tracking(self) -> str:
        return f"{self.root}/tracking"

    @property
    def joint_states(self) -> str:
        return f"{self.root}/joint_states"

    @property
    def head_command(self) -> str:
        return f"{self.root}/head/command"

    @property
    def eyes(self) -> str:
        return f"{self.root}/eyes"

    @property
    def eyes_frame(self) -> str:
        return f"{self.root}/eyes/frame"

    @property
    def arm_command(self) -> str:
        return f"{self.root}/arm/command"

    @property
    def events(self) -> str:
        return f"{self.root}/events"

    @property
    def status(self) -> str:
        return f"{self.root}/status"

    def events_history(self, node: str) -> str:
        """Queryable key of ``node``'s event history."""
        return f"{self.root}/events/history/{check_chunk(node, 'node name')}"

    @property
    def events_history_all(self) -> str:
        """Selector matching every node's event history queryable."""
        return f"{self.root}/events/history/*"

    def alive(self, node: str) -> str:
        """Liveliness token key of ``node``."""
        return f"{self.root}/alive/{check_chunk(node, 'node name')}"

    @property
    def alive_all(self) -> str:
        return f"{self.root}/alive/*"

    def node_of_alive(self, key: str) -> str | None:
        """The node name of a liveliness key, or ``None`` if ``key`` is not one of ours."""
        head = f"{self.root}/alive/"
        return key[len(head) :] if key.startswith(head) else None
