"""The ``RobotDriver`` interface: the engine's view of one robot, whatever carries the data.

A driver sends head commands, the gaze target, eye state or eye frames, the phase and arm
commands, and reads the robot's joint state, the tracking samples and the events of the other
nodes. Concrete kinds: :class:`~gazebot.io.drivers.zenoh_driver.ZenohRobotDriver` (any robot
bridge that speaks the ROS 2 topics of :mod:`gazebot.io.ros2.topics`) and
:class:`~gazebot.io.drivers.sim_driver.SimRobotDriver` (an in-process simulation, no bus).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

from gazebot.core.types import TrackingFrame
from gazebot.io.ros2.convert import RosCompressedImage
from gazebot.io.ros2.values import (
    ArmCommand,
    BusEvent,
    EyeState,
    JointGoal,
    JointState,
    NodeStatus,
    Point,
)

if TYPE_CHECKING:
    from gazebot.io.drivers.rmw.node import TypeMismatch
    from gazebot.io.drivers.tracking_source import Rival


class RobotDriver(ABC):
    """One robot as the gaze engine sees it.

    Attributes:
        node: This side's node name (the ``source`` of the events it publishes).
    """

    node: str = "engine"

    # -- ownership (one engine per robot) ------------------------------------------------
    def claim(self, timeout: float = 0.5) -> None:  # noqa: B027 - nothing to claim by default
        """Claim the robot's command topics (see :mod:`gazebot.io.drivers.ownership`), waiting
        up to ``timeout`` s to learn the other engines' claims."""

    def owns_robot(self) -> bool:
        """Whether this engine owns the robot (a driver without rivals always does)."""
        return True

    def rival_engines(self) -> list[str]:
        """The other engines claiming the robot, the earliest first."""
        return []

    # -- tracking sources --------------------------------------------------------------------
    def tracking_sources(self) -> dict[str, str]:
        """Tracking group -> the source whose samples are used (see
        :mod:`gazebot.io.drivers.tracking_source`); empty when the driver has one source."""
        return {}

    def tracking_rivals(self, new_only: bool = False) -> list[Rival]:
        """Sources whose tracking is ignored (:class:`~gazebot.io.drivers.tracking_source.Rival`;
        ``new_only``: those not returned before)."""
        return []

    # -- commands --------------------------------------------------------------------------
    @abstractmethod
    def send_head(self, goal: JointGoal) -> None:
        """Send head joint goals (rad)."""

    def send_gaze_target(self, t: float, point: Point) -> None:  # noqa: B027 - optional
        """Send the point looked at (m, robot base frame) at robot time ``t``."""

    def send_phase(self, t: float, phase: str, phase_start: float) -> None:  # noqa: B027
        """Send the handover phase (``idle`` ... ``done``), started at ``phase_start`` (s)."""

    @abstractmethod
    def send_eyes(self, eyes: EyeState) -> None:
        """Send the eye direction and blink for the robot's display to draw."""

    def send_eye_frame(self, image: RosCompressedImage) -> None:  # noqa: B027 - optional
        """Send a rendered display image, encoded (only when :meth:`wants_eye_frames`)."""

    def wants_eye_frames(self) -> bool:
        """True when the robot wants rendered display images rather than eye state only."""
        return False

    @abstractmethod
    def send_arm(self, cmd: ArmCommand) -> None:
        """Send an arm goal (or hand the arm back to the robot's own controller)."""

    # -- state -----------------------------------------------------------------------------
    @abstractmethod
    def wait_tracking(self, timeout: float) -> TrackingFrame | None:
        """The oldest unread tracking sample, waiting up to ``timeout`` s for one; ``None`` if
        none arrived. A driver keeps a short backlog and drops the oldest beyond it, so a slow
        engine lags by a bounded time."""

    @abstractmethod
    def joint_state(self) -> JointState | None:
        """The latest joint state, ``None`` before the first one."""

    # -- events and status -----------------------------------------------------------------
    @abstractmethod
    def poll_events(self) -> list[BusEvent]:
        """Events other nodes published since the last call (oldest first)."""

    @abstractmethod
    def publish_event(self, event: BusEvent) -> None:
        """Publish one of this node's events."""

    def event_history(self, timeout: float = 1.0) -> list[BusEvent]:
        """Events the other nodes have seen (e.g. after a restart), oldest first."""
        return []

    def publish_status(self, status: NodeStatus) -> None:  # noqa: B027 - optional capability
        """Publish this node's heartbeat."""

    def peers(self) -> dict[str, bool]:
        """Other nodes seen so far and whether they are alive."""
        return {}

    def dropped(self) -> dict[str, int]:
        """Malformed messages dropped so far, by topic."""
        return {}

    def type_mismatches(self) -> dict[str, TypeMismatch]:
        """Topics on which a publisher of another message type (or type version) was heard,
        each with what was expected and received (:class:`~gazebot.io.drivers.rmw.node.
        TypeMismatch`)."""
        return {}

    def callback_faults(self) -> dict[str, int]:
        """Subscription callbacks that raised (the message is lost, the driver goes on), by
        topic."""
        return {}

    def callback_fault_reasons(self) -> dict[str, str]:
        """The last exception of each topic's failing callback, one line."""
        return {}

    def close(self) -> None:  # noqa: B027 - nothing to release by default
        """Release the driver's resources (idempotent)."""

    def __enter__(self) -> RobotDriver:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
