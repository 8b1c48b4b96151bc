"""ROS 2 names as rmw_zenoh encodes them: topic resolution under a namespace with remapping
(``--remap FROM:=TO``) and ``/`` -> ``%`` mangling inside key chunks. (Type names and hashes are
:mod:`gazebot.io.ros2.names`'.)"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

_TOKEN = r"[A-Za-z_][A-Za-z0-9_]*"
_NAMESPACE = re.compile(rf"^(/|(/{_TOKEN})+)$")
_NODE = re.compile(rf"^{_TOKEN}$")
_TOPIC = re.compile(rf"^/?{_TOKEN}(/{_TOKEN})*$")


def check_namespace(namespace: str) -> str:
    """``namespace`` if it is an absolute ROS namespace (``/`` or ``/a/b``), else raise."""
    if not isinstance(namespace, str) or not _NAMESPACE.match(namespace):
        raise ValueError(
            f"bad ROS namespace {namespace!r}: expected '/' or /NAME[/NAME...] with letters, "
            "digits and '_' (not starting with a digit)"
        )
    return namespace


def check_node_name(name: str) -> str:
    """``name`` if it is a valid ROS node name (letters, digits, ``_``), else raise."""
    if not isinstance(name, str) or not _NODE.match(name):
        raise ValueError(f"bad ROS node name {name!r}: expected letters, digits and '_'")
    return name


def check_topic(name: str) -> str:
    """``name`` if it is a ROS topic name (relative ``a/b`` or absolute ``/a/b``), else raise."""
    if not isinstance(name, str) or not _TOPIC.match(name):
        raise ValueError(
            f"bad ROS topic name {name!r}: expected NAME[/NAME...], optionally starting with '/'"
        )
    return name


def mangle(name: str) -> str:
    """``name`` as one key chunk: every ``/`` becomes ``%`` (rmw_zenoh ``mangle_name``)."""
    return name.replace("/", "%")


def demangle(chunk: str) -> str:
    """A key chunk back to a name: every ``%`` becomes ``/`` (the inverse of :func:`mangle`)."""
    return chunk.replace("%", "/")


def parse_remap(rule: str) -> tuple[str, str]:
    """``FROM:=TO`` -> ``(FROM, TO)`` (both topic names); ``ValueError`` naming the rule."""
    if not isinstance(rule, str) or rule.count(":=") != 1:
        raise ValueError(f"bad remap {rule!r}: expected FROM:=TO, e.g. gaze_target:=/robot/look_at")
    src, dst = rule.split(":=")
    try:
        return check_topic(src), check_topic(dst)
    except ValueError as exc:
        raise ValueError(f"bad remap {rule!r}: {exc}") from None


@dataclass(frozen=True)
class Names:
    """Resolves gazebot's topic names for one robot.

    Attributes:
        namespace: Namespace of the nodes and of the relative topic names (default
            ``/gazebot``).
        remap: ``FROM -> TO`` rules; ``FROM`` matches a topic's relative or fully qualified
            name, ``TO`` is resolved against ``namespace`` when relative.
        domain_id: The ROS domain id (first chunk of every key).
        base_frame: The robot base frame's TF name: ``frame_id`` of every point gazebot sends
            and of the tracking it accepts (an empty ``frame_id`` is taken as this frame); the
            robot YAML's ``base_frame`` (``world`` by default).
        tf_frames: Tracked body (``giver_hand``, ...) -> TF child frame whose transform from
            :attr:`base_frame` on ``/tf`` gives its position (an alternative to the tracking
            topics; empty: ``/tf`` is not read).
    """

    namespace: str = "/gazebot"
    remap: Mapping[str, str] = field(default_factory=dict)
    domain_id: int = 0
    base_frame: str = "world"
    tf_frames: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_namespace(self.namespace)
        for src, dst in self.remap.items():
            check_topic(src)
            check_topic(dst)
        if not isinstance(self.domain_id, int) or not 0 <= self.domain_id <= 232:
            raise ValueError(f"ROS domain id must be an integer 0..232, got {self.domain_id!r}")
        if not isinstance(self.base_frame, str) or not self.base_frame.strip("/"):
            raise ValueError(f"base frame must be a TF frame name, got {self.base_frame!r}")
        object.__setattr__(self, "remap", dict(self.remap))
        object.__setattr__(self, "tf_frames", dict(self.tf_frames))

    @classmethod
    def from_rules(cls, namespace: str = "/gazebot", rules: Iterable[str] = (),
                   domain_id: int = 0, **kw: object) -> Names:
        """Names with ``--remap`` rules given as ``FROM:=TO`` strings."""
        return cls(namespace, dict(parse_remap(r) for r in rules), domain_id, **kw)  # type: ignore[arg-type]

    def is_base_frame(self, frame_id: str) -> bool:
        """Whether ``frame_id`` names the base frame (empty or with a leading ``/``: too)."""
        return frame_id.lstrip("/") in ("", self.base_frame.lstrip("/"))

    def qualify(self, name: str) -> str:
        """The fully qualified name of ``name`` in :attr:`namespace` (no remapping)."""
        check_topic(name)
        if name.startswith("/"):
            return name
        return f"{self.namespace.rstrip('/')}/{name}"

    def resolve(self, name: str) -> str:
        """The fully qualified topic name of ``name`` after remapping."""
        fq = self.qualify(name)
        for src, dst in self.remap.items():
            if src == name or self.qualify(src) == fq:
                return self.qualify(dst)
        return fq

    def key(self, topic: str, dds_type: str, type_hash: str) -> str:
        """The data key expression of a resolved ``topic`` carrying ``dds_type``."""
        return f"{self.domain_id}/{topic.lstrip('/')}/{dds_type}/{type_hash}"

    def key_any_type(self, topic: str) -> str:
        """Key expression matching ``topic`` whatever its type (to report mismatches)."""
        return f"{self.domain_id}/{topic.lstrip('/')}/*/*"
