"""The gaze engine against a kinematic head: a synthetic handover for any robot YAML.

For a robot gazebot has no MuJoCo scene for (a URDF robot, docs/your-robot.md) the head is
kinematic: each tick it takes the engine's head command exactly, and the gaze it then has
(forward kinematics of the head command, the eyes turned by the eye command) is measured
against the target. The giver is synthetic: a face at the robot's ``face`` point and a hand
that reaches from the giver's body to the robot's ``handover_location``, holds, and withdraws.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gazebot.core.engine import GazeEngine
from gazebot.core.kinematics.eyes import angle_between, eye_direction
from gazebot.core.kinematics.robot import RobotModel
from gazebot.core.minimum_jerk import minimum_jerk
from gazebot.core.types import TrackingFrame


@dataclass(frozen=True)
class HandoverScript:
    """Timing of the synthetic giver (s)."""

    duration: float = 8.0
    rate: float = 30.0
    reach_start: float = 2.0
    reach_time: float = 1.2
    hold_until: float = 5.0
    withdraw_time: float = 1.0


def synthetic_handover(robot: RobotModel, script: HandoverScript | None = None
                       ) -> list[TrackingFrame]:
    """The tracking frames of a synthetic giver in front of ``robot``: the face at the robot's
    ``face`` point, the hand starting below it at the height of ``handover_location``, reaching
    to 5 cm short of it (minimum jerk; the robot's hand waits there), holding, then
    withdrawing."""
    s = script or HandoverScript()
    face = robot.points["face"]
    meet = robot.points["handover_location"]
    start = np.array([face[0], face[1], meet[2]])
    hand_meet = meet + 0.05 * (start - meet) / max(float(np.linalg.norm(start - meet)), 1e-9)
    frames = []
    for k in range(int(round(s.duration * s.rate)) + 1):
        t = k / s.rate
        reach = minimum_jerk((t - s.reach_start) / s.reach_time)
        back = minimum_jerk((t - s.hold_until) / s.withdraw_time)
        share = reach - back
        hand = start + share * (hand_meet - start)
        # The robot's hand waits at the handover location (what the phase detector measures the
        # giver's reach against).
        frames.append(TrackingFrame.make(t, giver_hand=hand, receiver_hand=meet, giver_face=face))
    return frames


@dataclass(frozen=True)
class KinematicTick:
    """One tick of the kinematic head (rad, m).

    Attributes:
        t: Time (s).
        phase, target: The engine's phase and target kind.
        target_point: The point looked at (base frame).
        head: Head joint positions (the engine's command, taken exactly).
        eye_yaw, eye_pitch: Eye command (gaze frame).
        eye_joints: Eye joint positions for eyes that are joints (empty otherwise).
        miss: Angle between the measured gaze (head forward kinematics + eyes) and the target.
    """

    t: float
    phase: str
    target: str
    target_point: np.ndarray
    head: dict[str, float]
    eye_yaw: float
    eye_pitch: float
    eye_joints: dict[str, float]
    miss: float


def run_kinematic_head(
    robot: RobotModel, frames: list[TrackingFrame], behavior: str | Path = "face-hand-face"
) -> list[KinematicTick]:
    """Feed ``frames`` to a gaze engine on ``robot`` and measure the gaze each tick."""
    from gazebot.core.behaviors import load_behavior

    engine = GazeEngine(robot, load_behavior(behavior))
    ticks = []
    for frame in frames:
        cmd = engine.step(frame)
        q = robot.head_vector(cmd.head)
        pose = robot.gaze_pose(q)
        sight = pose.rotation @ eye_direction(cmd.eye_yaw, cmd.eye_pitch)
        point = np.asarray(cmd.target_point, dtype=float)
        miss = angle_between(sight, point - pose.position)
        ticks.append(
            KinematicTick(
                t=cmd.t, phase=getattr(cmd.phase, "value", str(cmd.phase)), target=cmd.target,
                target_point=point,
                head=dict(cmd.head), eye_yaw=cmd.eye_yaw, eye_pitch=cmd.eye_pitch,
                eye_joints=robot.eye_joint_positions(cmd.eye_yaw, cmd.eye_pitch), miss=miss,
            )
        )
    return ticks


def write_kinematic_csv(ticks: list[KinematicTick], path: Path) -> None:
    """The ticks as CSV: time, phase, target, target point, head and eye joints (deg), miss
    (deg)."""
    import csv

    head = list(ticks[0].head) if ticks else []
    eyes = list(ticks[0].eye_joints) if ticks else []
    with path.open("w", newline="") as fh:
        out = csv.writer(fh)
        out.writerow(["t", "phase", "target", "x", "y", "z", *[f"{n}_deg" for n in head],
                      "eye_yaw_deg", "eye_pitch_deg", *[f"{n}_deg" for n in eyes], "miss_deg"])
        for k in ticks:
            out.writerow([
                f"{k.t:.4f}", k.phase, k.target, *(f"{v:.4f}" for v in k.target_point),
                *(f"{math.degrees(k.head[n]):.3f}" for n in head),
                f"{math.degrees(k.eye_yaw):.3f}", f"{math.degrees(k.eye_pitch):.3f}",
                *(f"{math.degrees(k.eye_joints[n]):.3f}" for n in eyes),
                f"{math.degrees(k.miss):.4f}",
            ])
