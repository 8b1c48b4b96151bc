"""The in-process handover recording shared by ``gazebot demo``, ``gazebot render video`` and the
study's renders: the simulation runs the handover, :class:`gazebot.core.runtime.GazeLoop` (the same
loop that drives a robot on the bus) commands head, eyes and blinks every control tick, and an
observer camera records an H.264 MP4 (yuv420p) off-screen.

Deterministic for a seed: the giver's timing, the engine's random choices and the blinks all derive
from it, and physics and software rendering are deterministic. The video is written atomically
(:func:`gazebot.apps.render.video.open_h264_writer`): a failed run leaves no file behind.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from contextlib import nullcontext
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from gazebot.apps.render.timeline import TickRecord
from gazebot.apps.render.video_settings import VIDEO
from gazebot.core.defaults import DEFAULT_BEHAVIOR, DEFAULT_ROBOT
from gazebot.core.kinematics.robot_config import RobotConfig
from gazebot.core.runtime import GazeLoop
from gazebot.core.types import Event, Phase

if TYPE_CHECKING:
    from typing import Any

    from gazebot.apps.sim.simulation import HandoverSimulation
    from gazebot.core.types import TrackingFrame

    # t, tracking frame, measured joints, robot events, the loop's command (None: unsafe).
    StepObserver = Callable[[float, TrackingFrame, dict[str, float], list[Event], Any], None]

CONTROL_HZ = 120.0  # tracking rate of the seed's motion capture setup
MAX_DURATION_S = 30.0  # a handover that has not finished by then is cut (and reported)
# After the simulated handover ends, the engine confirms it from the tracking (the giver's hand
# back at rest): wait this long at most for that before the tail.
CONFIRM_WAIT_S = 4.0


@dataclass
class HandoverRecording:
    """Result of :func:`record_handover`."""

    ticks: list[TickRecord]
    video: Path | None
    frames: int
    fps: float
    width: int
    height: int
    completed: bool  # the handover finished before MAX_DURATION_S
    robot_events: list[Event] = field(default_factory=list)


def check_video_size(width: int, height: int, fps: float) -> None:
    """Raise ``ValueError`` unless ``width`` x ``height`` px at ``fps`` is a video we record."""
    for name, v in (("width", width), ("height", height)):
        if isinstance(v, bool) or not isinstance(v, int) or v < 16 or v % 2:
            raise ValueError(f"video {name} must be an even number of pixels >= 16, got {v!r}")
    if not (math.isfinite(fps) and 1.0 <= fps <= CONTROL_HZ):
        raise ValueError(f"fps must be between 1 and {CONTROL_HZ:g}, got {fps}")


def simulated_end(sim: HandoverSimulation, dt: float) -> float:
    """When (s) the handover of ``sim``, a fresh simulation, ends: ``sim`` stepped by ``dt``
    without gaze (the head does not change when the giver and the arm act) until it is done,
    at most :data:`MAX_DURATION_S`. The progress bar's total comes from it: a few tenths of a
    second of simulation, where an estimate from the giver's plan was a few frames off."""
    while not sim.done and sim.t < MAX_DURATION_S:
        sim.step(dt)
    return float(sim.t)


def record_handover(
    robot: str | Path | RobotConfig = DEFAULT_ROBOT,
    behavior: str | Path = DEFAULT_BEHAVIOR,
    scene: str | Path = "default",
    out_path: str | Path | None = None,
    seed: int = 0,
    width: int = VIDEO.width,
    height: int = VIDEO.height,
    fps: float = VIDEO.fps,
    progress: bool = True,
    on_tick: Callable[[HandoverSimulation, TickRecord], None] | None = None,
    loop: GazeLoop | None = None,
    on_step: StepObserver | None = None,
    giver_factory=None,
) -> HandoverRecording:
    """Run one handover with the gaze engine in the loop; record the video when ``out_path``.

    ``robot`` is a name, a robot YAML path or a parsed config; it is loaded once and the same
    config drives the simulation, the gaze engine and the eye display. ``on_tick(sim, tick)``,
    when given, sees the simulation after each control tick's head and eye commands (e.g. to
    inspect or render it); it must not step the simulation. ``loop`` replaces the default
    :class:`~gazebot.core.runtime.GazeLoop` (``behavior`` and ``seed`` for its engine and blinks);
    it must be built for the same robot. ``giver_factory`` replaces the simulated giver (see
    :class:`HandoverSimulation`; e.g. recorded motion, ``--giver-motion``). ``on_step(t,
    frame, joints, robot_events, cmd)``, when given, sees every control tick's input and the
    loop's command (``None`` when none was safe to send), e.g. to record them as ROS 2 messages.

    Returns the per-tick timeline, the frame count and the robot's events.
    """
    from gazebot.apps.render.gl_check import ensure_gl_backend

    ensure_gl_backend()
    from gazebot.apps.render.progress import FrameProgress
    from gazebot.apps.render.video import open_h264_writer
    from gazebot.apps.sim.robot import load_sim_robot
    from gazebot.apps.sim.simulation import HandoverSimulation

    check_video_size(width, height, fps)
    sim_robot = load_sim_robot(robot)
    def new_sim() -> HandoverSimulation:
        return HandoverSimulation(
            robot=sim_robot, scene=scene, seed=seed, giver_factory=giver_factory
        )

    dt = 1.0 / CONTROL_HZ
    end_s = None
    if progress and out_path is not None:
        dry = new_sim()
        try:
            end_s = simulated_end(dry, dt) + dry.config.tail_s
        finally:
            dry.close()
    sim = new_sim()
    if loop is None:
        loop = GazeLoop.from_config(robot=sim_robot.spec, behavior=behavior, seed=seed)
    tail = sim.config.tail_s
    ticks: list[TickRecord] = []
    events: list[Event] = []
    frames, done_at, sim_done_at = 0, None, None
    phase = None
    label = f"{sim_robot.name} {Path(str(behavior)).stem}"
    try:
        writer_ctx = (
            open_h264_writer(out_path, fps, (width, height))
            if out_path is not None
            else nullcontext(None)
        )
        with (
            writer_ctx as writer,
            FrameProgress(fps, end_s or 0.0, desc=label, enabled=end_s is not None) as bar,
        ):
            while True:
                frame = sim.tracking()
                robot_events = sim.robot_events()
                events.extend(robot_events)
                loop.notify(robot_events)
                # The measured arm pose: on Sawyer the head rides on right_j0.
                cmd = loop.tick(frame, joints=sim.joint_state())
                if cmd is not None:  # None: an unsafe command, never applied
                    sim.apply_head(cmd.head)
                    sim.apply_eyes(cmd.eye_yaw, cmd.eye_pitch, cmd.blink, cmd.distance)
                    state = sim.joint_state()
                    ticks.append(
                        TickRecord(
                            t=sim.t,
                            phase=cmd.phase.value,
                            target=cmd.target,
                            head=dict(cmd.head),
                            eye_yaw=cmd.eye_yaw,
                            eye_pitch=cmd.eye_pitch,
                            target_point=cmd.target_point.copy(),
                            hand=sim.giver.hand.copy(),
                            face=sim.face_point.copy(),
                            head_measured={j: state[j] for j in cmd.head if j in state},
                            events=tuple(e.kind.value for e in cmd.events),
                            reach_start_time=(
                                math.nan if sim.reach_start_time is None else sim.reach_start_time
                            ),
                        )
                    )
                if on_step is not None:  # the tick's input and answer (the sim has not moved)
                    on_step(frame.t, frame, sim.joint_state(), robot_events, cmd)
                if on_tick is not None and ticks:
                    on_tick(sim, ticks[-1])
                # Frame k shows the first tick at or after k / fps.
                if writer is not None and sim.t >= frames / fps - 1e-9:
                    writer.append(sim.render(width=width, height=height))
                    frames += 1
                    bar.advance(done_at + tail if done_at is not None else None)
                if cmd is not None:
                    phase = cmd.phase
                if sim_done_at is None and sim.done:
                    sim_done_at = sim.t
                # The video ends a tail after the engine too has seen the handover end.
                confirmed = phase is Phase.DONE or (
                    sim_done_at is not None and sim.t >= sim_done_at + CONFIRM_WAIT_S
                )
                if done_at is None and sim_done_at is not None and confirmed:
                    done_at = sim.t
                if (done_at is not None and sim.t >= done_at + tail) or sim.t >= MAX_DURATION_S:
                    break
                sim.step(dt)
            bar.finish()
    finally:
        sim.close()
    return HandoverRecording(
        ticks=ticks,
        video=Path(out_path) if out_path is not None else None,
        frames=frames,
        fps=fps,
        width=width,
        height=height,
        completed=sim_done_at is not None,
        robot_events=events,
    )


def render_handover_video(
    robot: str | Path | RobotConfig,
    behavior: str | Path,
    scene: str | Path,
    out_path: str | Path,
    seed: int = 0,
    width: int = VIDEO.width,
    height: int = VIDEO.height,
    fps: float = VIDEO.fps,
    progress: bool = True,
    giver_factory=None,
) -> Path:
    """Render one full handover to ``out_path`` (H.264 MP4, yuv420p) and return the path; on an
    error no file is left at ``out_path``. ``giver_factory``: see :func:`record_handover`."""
    record_handover(
        robot, behavior, scene, out_path, seed, width, height, fps, progress,
        giver_factory=giver_factory,
    )
    return Path(out_path)
