"""The one runtime loop from tracking to the robot's head, eyes and lids (:class:`GazeLoop`),
shared by the video recordings, the engine node on the bus and the in-process drivers."""

from __future__ import annotations

from gazebot.core.runtime.loop import EngineLike, GazeLoop, LoopCommand, RobotLike
from gazebot.core.types import TrackingState

__all__ = ["EngineLike", "GazeLoop", "LoopCommand", "RobotLike", "TrackingState"]
