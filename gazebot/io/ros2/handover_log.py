"""One control tick of a handover -> the ROS 2 messages of every gazebot topic, into an MCAP
file: what ``gazebot demo`` records beside its video, on the topics and types a robot running
gazebot over ROS 2 publishes (:mod:`gazebot.io.ros2.topics`).

Log time is the run's wall clock when the tick is written, as ``ros2 bag record`` stamps what it
receives; the robot's (simulation) time stays in the messages' header stamps, as stacks with
``use_sim_time`` expect. Per tick (header stamps at the tick's robot time): the tracked bodies
(``PointStamped``), gripper state and load share, ``/joint_states``, the robot's events, and
the engine's answer (``head/command``, ``gaze_target``, ``eyes/state``, ``handover/events``,
``handover/phase``); ``/diagnostics`` once per ``diagnostics_period``; the eye display
(``CompressedImage``, JPEG) once per ``eye_image_period`` when an eye renderer is given.

With the robot model, the file also holds what Foxglove's 3D panel (or rviz2) needs to draw
robot, hands and gaze from the file alone: ``/robot_description`` (once, first: a URDF of the
head chain, :mod:`gazebot.io.ros2.head_urdf`), ``/tf_static`` (once: the gaze frame), and once
per ``scene_period`` ``/tf`` (the head joints' frames at the commanded head position,
:mod:`gazebot.io.ros2.tf`) and ``markers`` (gaze ray and target, hands, face, the phase:
:mod:`gazebot.io.ros2.markers`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from gazebot.core.kinematics.robot import RobotModel
from gazebot.core.types import Event, GazeCommand, Phase, TrackingFrame
from gazebot.io.ros2 import convert as cv
from gazebot.io.ros2 import topics as tp
from gazebot.io.ros2.head_urdf import head_chain_urdf
from gazebot.io.ros2.markers import Scene, marker_array
from gazebot.io.ros2.mcap_writer import McapRecorder
from gazebot.io.ros2.tf import HeadFrames, tf_message
from gazebot.io.ros2.values import NodeStatus

#: Seconds of robot time between ``/tf`` and ``markers`` messages (30 Hz, as on the bus).
SCENE_PERIOD_S = 1.0 / 30.0


def _next_slot(t: float, period: float) -> float:
    """The first multiple of ``period`` after ``t`` (less 1 ns: tick times are sums
    of floats), so a periodic topic keeps its rate on any tick grid."""
    return (math.floor(t / period + 1e-9) + 1) * period - 1e-9


class HandoverMcap:
    """Writes each tick of a handover to ``path`` as ROS 2 messages.

    Args:
        path: The ``.mcap`` file.
        base_frame: ROS name of the robot base frame (``RobotConfig.base_frame``).
        gaze_frame: ROS name of the head's gaze frame (``RobotConfig.gaze_site``).
        time_from_start: ``head/command``'s time to reach the goal (s): the control period.
        namespace: The topics' namespace.
        eye_image: ``(yaw, pitch, blink, distance) -> RGB image`` of the head display, or
            ``None`` to record no eye images.
        eye_image_period: Seconds between eye images.
        diagnostics_period: Seconds between ``/diagnostics`` messages.
        node: The node name in diagnostics and as the source of events.
        clock: The wall clock of the log times (s since the epoch).
        robot: The robot model the engine steers by (its own instance: its arm pose follows the
            recorded joint states), for ``/robot_description``, ``/tf``, ``/tf_static`` and
            ``markers``; ``None`` records none of them.
        scene_period: Seconds of robot time between ``/tf`` and ``markers`` messages.
    """

    def __init__(
        self,
        path: str | Path,
        base_frame: str,
        gaze_frame: str,
        time_from_start: float,
        namespace: str = tp.DEFAULT_NAMESPACE,
        eye_image: Callable[[float, float, float, float | None], np.ndarray] | None = None,
        eye_image_period: float = 0.1,
        diagnostics_period: float = 1.0,
        node: str = "engine",
        clock: Callable[[], float] = time.time,
        robot: RobotModel | None = None,
        scene_period: float = SCENE_PERIOD_S,
    ) -> None:
        self.recorder = McapRecorder(path)
        self.base_frame = base_frame
        self.gaze_frame = gaze_frame
        self.time_from_start = time_from_start
        self.namespace = namespace
        self.eye_image = eye_image
        self.eye_image_period = eye_image_period
        self.diagnostics_period = diagnostics_period
        self.node = node
        self.clock = clock
        self._phase: tuple[Phase, float] | None = None  # (phase, its start)
        self._next_image = -math.inf
        self._next_diag = -math.inf
        self._t0: float | None = None
        self.robot = robot
        self.frames = HeadFrames(robot, base_frame) if robot is not None else None
        self.scene_period = scene_period
        self._next_scene = -math.inf

    def _write(self, topic: tp.Topic, msg: object) -> None:
        self.recorder.write(topic.resolve(self.namespace), msg, self.clock())

    def tick(
        self,
        t: float,
        frame: TrackingFrame | None,
        joints: Mapping[str, float] | None,
        robot_events: Sequence[Event],
        cmd: GazeCommand | None,
    ) -> None:
        """Record one tick at robot time ``t`` (s): its input (``frame``, measured ``joints``,
        ``robot_events``) and the engine's command (``None``: none was sent)."""
        if self._t0 is None:
            self._t0 = t
            self._write_description(t)
        if frame is not None:
            for body, p in cv.tracking_points(frame).items():
                self._write(tp.TRACKING[body], cv.point_stamped(frame.t, p, self.base_frame))
            if frame.gripper_closed is not None:
                self._write(tp.GRIPPER, cv.gripper_state(frame.t, frame.gripper_closed))
            if frame.load_share is not None:
                self._write(tp.LOAD_SHARE, cv.load_share(frame.t, frame.load_share))
        if joints:
            self._write(tp.JOINT_STATES, cv.joint_state(t, joints))
            if self.robot is not None:
                self.robot.set_arm(joints)  # the arm carries the head (Sawyer's right_j0)
        for event in robot_events:
            self._write(tp.ROBOT_EVENTS, cv.event_msg(event, "robot", t))
        if cmd is None:
            return
        msgs = cv.command_messages(cmd, self.base_frame, self.gaze_frame, self.time_from_start)
        if msgs.head is not None:
            self._write(tp.HEAD_COMMAND, msgs.head)
        if msgs.gaze_target is not None:
            self._write(tp.GAZE_TARGET, msgs.gaze_target)
        self._write(tp.EYES, msgs.eyes)
        for msg in msgs.events:
            self._write(tp.EVENTS, msg)
        phase, source = cv.command_phase(cmd)
        if self._phase is None or self._phase[0] is not phase:
            self._phase = (phase, float(cmd.t))
        self._write(tp.PHASE, cv.handover_phase(float(cmd.t), phase, self._phase[1],
                                                source=source))
        if self.eye_image is not None and t >= self._next_image:
            self._next_image = _next_slot(t, self.eye_image_period)
            img = self.eye_image(cmd.eye_yaw, cmd.eye_pitch, cmd.blink, cmd.distance)
            self._write(tp.EYE_IMAGE, cv.compressed_image(img, t, "display"))
        if self.frames is not None and t >= self._next_scene:
            self._next_scene = _next_slot(t, self.scene_period)
            self._write_scene(cmd, phase, frame)
        if t >= self._next_diag:
            self._next_diag = _next_slot(t, self.diagnostics_period)
            status = NodeStatus(
                node=self.node, state=cmd.status, tracking=cmd.tracking, phase=phase.value,
                uptime=t - self._t0,
            )
            self._write(tp.DIAGNOSTICS, cv.diagnostics(status, t))

    def _write_description(self, t: float) -> None:
        """The latched topics, once at the start: the head chain's URDF and the gaze frame."""
        if self.robot is None or self.frames is None:
            return
        urdf = head_chain_urdf(self.robot, self.base_frame)
        self._write(tp.ROBOT_DESCRIPTION, cv.RosString(data=urdf))
        self._write(tp.TF_STATIC, tf_message(t, self.frames.static()))

    def _write_scene(self, cmd: GazeCommand, phase: Phase, frame: TrackingFrame | None) -> None:
        """``/tf`` (head joints at the command) and ``markers`` of one tick."""
        assert self.frames is not None
        self._write(tp.TF, tf_message(cmd.t, self.frames.moving(cmd.head)))
        gaze = self.frames.gaze_pose(cmd.head)
        scene = Scene(
            cmd.t, phase.value, gaze.position, cmd.target_point,
            giver_hand=frame.giver_hand if frame is not None else None,
            giver_face=frame.giver_face if frame is not None else None,
            receiver_hand=frame.receiver_hand if frame is not None else None)
        self._write(tp.MARKERS, marker_array(scene, self.base_frame))

    def close(self) -> Path:
        """Finish the file; returns its path."""
        return self.recorder.close()

    def abort(self) -> None:
        """Drop the partial file (a failed run)."""
        self.recorder.abort()
