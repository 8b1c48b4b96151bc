"""The engine's scene on the bus for the ROS 2 stack's tools (rviz2, Foxglove, ``gazebot
view``): the commanded head joints' frames on ``/tf``, the ``gaze`` frame on ``/tf_static``
(latched) and the gaze ray, gaze target, hands, face and phase on ``markers``
(:mod:`gazebot.io.ros2.tf`, :mod:`gazebot.io.ros2.markers`)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from gazebot.core.kinematics.robot import RobotModel
from gazebot.core.types import GazeCommand, TrackingFrame
from gazebot.io.drivers.rmw.node import RosNode
from gazebot.io.ros2 import topics
from gazebot.io.ros2.markers import Scene, marker_array
from gazebot.io.ros2.tf import HeadFrames, tf_message

#: How often the scene is sent (Hz): enough for a viewer, a fraction of the engine's rate.
SCENE_RATE_HZ = 30.0


class SceneOut:
    """Publishes the scene of the engine's commands on ``ros``.

    Args:
        ros: The engine's ROS node (its namespace's ``markers``; ``/tf``, ``/tf_static``).
        robot: The robot model the engine steers by.
        rate: Largest rate the scene is sent at (Hz).
        clock: Monotonic clock (s).
    """

    def __init__(self, ros: RosNode, robot: RobotModel, rate: float = SCENE_RATE_HZ,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if not (math.isfinite(rate) and rate > 0):
            raise ValueError(f"scene rate must be a positive number of Hz, got {rate!r}")
        self.base_frame = ros.names.base_frame
        self.frames = HeadFrames(robot, self.base_frame)
        self.period = 1.0 / rate
        self.clock = clock
        self.sent = 0
        self._tf = ros.publisher(topics.TF.name, topics.TF.type)
        self._static = ros.publisher(topics.TF_STATIC.name, topics.TF_STATIC.type)
        self._markers = ros.publisher(topics.MARKERS.name, topics.MARKERS.type)
        self._static_sent = False
        self._last = -math.inf

    def send(self, cmd: GazeCommand, phase: str, frame: TrackingFrame | None) -> bool:
        """Send the scene of ``cmd`` (and the tracked points of ``frame``) unless one was sent
        less than a period ago; returns whether it was sent."""
        now = self.clock()
        if now - self._last < self.period:
            return False
        self._last = now
        if not self._static_sent:  # latched: once is enough, late subscribers get it too
            self._static.publish(tf_message(cmd.t, self.frames.static()))
            self._static_sent = True
        self._tf.publish(tf_message(cmd.t, self.frames.moving(cmd.head)))
        gaze = self.frames.gaze_pose(cmd.head)
        scene = Scene(
            cmd.t, phase, gaze.position, cmd.target_point,
            giver_hand=frame.giver_hand if frame is not None else None,
            giver_face=frame.giver_face if frame is not None else None,
            receiver_hand=frame.receiver_hand if frame is not None else None)
        self._markers.publish(marker_array(scene, self.base_frame))
        self.sent += 1
        return True
