"""QoS profiles and their encoding in rmw_zenoh's liveliness tokens.

The token's last chunk is ``<reliability>:<durability>:<history>,<depth>:<deadline s>,<ns>:
<lifespan s>,<ns>:<liveliness>,<lease s>,<ns>`` where every value equal to rmw_zenoh's default
profile is left empty (``qos_to_keyexpr`` in rmw_zenoh_cpp's ``liveliness_utils.cpp``).
Enum values are rmw's (``rmw/types.h``).
"""

from __future__ import annotations

from dataclasses import dataclass

RELIABLE, BEST_EFFORT = 1, 2
TRANSIENT_LOCAL, VOLATILE = 1, 2
KEEP_LAST, KEEP_ALL = 1, 2
AUTOMATIC = 1
#: rmw's infinite duration (s, ns).
INFINITE = (9223372036, 854775807)


@dataclass(frozen=True)
class QosProfile:
    """A topic's QoS (rmw enum values; durations as ``(s, ns)``)."""

    reliability: int = RELIABLE
    durability: int = VOLATILE
    history: int = KEEP_LAST
    depth: int = 10
    deadline: tuple[int, int] = INFINITE
    lifespan: tuple[int, int] = INFINITE
    liveliness: int = AUTOMATIC
    lease: tuple[int, int] = INFINITE

    @property
    def transient_local(self) -> bool:
        """Whether a late subscription receives the last ``depth`` samples (latched)."""
        return self.durability == TRANSIENT_LOCAL

    @property
    def reliable(self) -> bool:
        """Whether the reliability is reliable (else best effort)."""
        return self.reliability == RELIABLE

    def encode(self) -> str:
        """The token chunk, values equal to :data:`RMW_ZENOH_DEFAULT` left empty."""
        d = RMW_ZENOH_DEFAULT

        def val(mine: int, default: int) -> str:
            return "" if mine == default else str(mine)

        return ":".join(
            (
                val(self.reliability, d.reliability),
                val(self.durability, d.durability),
                f"{val(self.history, d.history)},{val(self.depth, d.depth)}",
                f"{val(self.deadline[0], d.deadline[0])},{val(self.deadline[1], d.deadline[1])}",
                f"{val(self.lifespan[0], d.lifespan[0])},{val(self.lifespan[1], d.lifespan[1])}",
                f"{val(self.liveliness, d.liveliness)},{val(self.lease[0], d.lease[0])},"
                f"{val(self.lease[1], d.lease[1])}",
            )
        )

    @classmethod
    def decode(cls, chunk: str) -> QosProfile:
        """Parse a token's QoS chunk (empty values: rmw_zenoh's defaults); ``ValueError``."""
        parts = chunk.split(":")
        if len(parts) != 6:
            raise ValueError(f"bad QoS chunk {chunk!r}: expected 6 ':'-separated fields")
        d = RMW_ZENOH_DEFAULT

        def ints(text: str, n: int, defaults: tuple[int, ...]) -> tuple[int, ...]:
            vals = text.split(",")
            if len(vals) != n:
                raise ValueError(f"bad QoS chunk {chunk!r}: field {text!r} needs {n} values")
            return tuple(int(v) if v else dv for v, dv in zip(vals, defaults, strict=True))

        (rel,) = ints(parts[0], 1, (d.reliability,))
        (dur,) = ints(parts[1], 1, (d.durability,))
        hist, depth = ints(parts[2], 2, (d.history, d.depth))
        deadline = ints(parts[3], 2, d.deadline)
        lifespan = ints(parts[4], 2, d.lifespan)
        live, *lease = ints(parts[5], 3, (d.liveliness, *d.lease))
        return cls(rel, dur, hist, depth, (deadline[0], deadline[1]),
                   (lifespan[0], lifespan[1]), live, (lease[0], lease[1]))


#: rmw_zenoh's default profile, against which tokens elide values (rmw_zenoh_cpp ``qos.cpp``:
#: keep last 42, reliable, volatile, infinite durations, automatic liveliness).
RMW_ZENOH_DEFAULT = QosProfile(depth=42)

#: What gazebot's publishers and subscriptions use: ROS 2's default profile (reliable, volatile,
#: keep last 10), so ``ros2 topic echo`` with its defaults matches.
DEFAULT = QosProfile()

#: A latched topic as ``robot_state_publisher`` publishes ``/robot_description`` and
#: ``tf2_ros::StaticTransformBroadcaster`` ``/tf_static``: reliable, transient local, keep last 1.
LATCHED = QosProfile(durability=TRANSIENT_LOCAL, depth=1)

#: Period of the sporadic heartbeat of a reliable transient-local publisher (s): rmw_zenoh's
#: ``SAMPLE_MISS_DETECTION_HEARTBEAT_PERIOD`` (500 ms), sent only when a sample was published
#: since the last one, so a subscriber detects a lost last sample and fetches it from the cache.
HEARTBEAT_S = 0.5


def qos_of(durability: str, depth: int) -> QosProfile:
    """The reliable keep-last profile of ``durability`` (``volatile`` or ``transient_local``)
    and ``depth``; ``ValueError`` naming what was expected."""
    kinds = {"volatile": VOLATILE, "transient_local": TRANSIENT_LOCAL}
    if durability not in kinds:
        raise ValueError(f"durability must be 'volatile' or 'transient_local', got {durability!r}")
    if not (isinstance(depth, int) and depth > 0):
        raise ValueError(f"QoS depth must be a positive integer, got {depth!r}")
    return QosProfile(durability=kinds[durability], depth=depth)
