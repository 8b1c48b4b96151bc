"""A kinematic robot-giver scene: the BIP drives the robot's two end effectors toward a person
while the gaze engine runs in the loop, as in every gazebot scene (the same
:class:`~gazebot.core.runtime.GazeLoop` the simulation and the bus use).

Per control tick (120 Hz): the person's wrists come from a demonstration (the receiver's part),
the filter takes them as its observation, and the robot's wrists go to the filter's current
estimate of its own (the giver's part at the estimated phase). The tracking frame is the
robot-to-human one of :meth:`gazebot.apps.sim.simulation.HandoverSimulation.tracking`: the person
is in the ``giver_*`` fields (the robot looks at their face and hands), the object (between the
robot's hands) in ``receiver_hand``, and the grip and load share are the taker's. Once the
demonstration ends the person holds the object with the robot for ``share_s``, the robot lets go
and the person carries it back to where their hands started.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gazebot.apps.bip.demos import GIVER_DOFS, RATE_HZ, RECEIVER_DOFS, Demonstration
from gazebot.apps.bip.enbip import ConstraintMode, EnsembleBIP, FilterConfig
from gazebot.apps.bip.prior import BipPrior
from gazebot.apps.render.timeline import TickRecord
from gazebot.apps.sim.motion import MinJerkSegment
from gazebot.core.runtime import GazeLoop
from gazebot.core.types import Event, EventKind, TrackingFrame


@dataclass(frozen=True)
class SceneConfig:
    """Timing (s) and the person's face (m, robot base frame) of the kinematic scene."""

    lead_s: float = 0.5  # everyone still before the reach
    share_s: float = 0.4  # both hold the object
    retreat_s: float = 0.9  # the person's retreat
    tail_s: float = 1.5
    face: tuple[float, float, float] = (1.15, 0.0, 1.55)


@dataclass
class SceneRun:
    """What the scene produced: the engine's timeline, the robot's wrists, the grip width kept."""

    ticks: list[TickRecord] = field(default_factory=list)
    robot_wrists: list[np.ndarray] = field(default_factory=list)
    events: list[Event] = field(default_factory=list)
    width: float = float("nan")

    def grip_width_error(self) -> np.ndarray:
        """| |left - right| - width | per tick of the reach (m)."""
        w = np.array(self.robot_wrists)
        return np.abs(np.linalg.norm(w[:, :3] - w[:, 3:], axis=1) - self.width)


def run_scene(
    prior: BipPrior,
    demo: Demonstration,
    mode: ConstraintMode | str = ConstraintMode.FILTER,
    loop: GazeLoop | None = None,
    config: SceneConfig | None = None,
    filter_config: FilterConfig | None = None,
    seed: int = 0,
) -> SceneRun:
    """Run one robot-to-human handover of ``demo``'s object with the BIP and the gaze engine."""
    cfg = config or SceneConfig()
    loop = loop or GazeLoop.from_config(robot="sawyer", behavior="face-hand-face", seed=seed)
    fcfg = filter_config or FilterConfig()
    bip = EnsembleBIP(prior, fcfg, mode=mode, width=demo.width, seed=seed)
    obs = list(fcfg.observed)
    dt = 1.0 / RATE_HZ
    face = np.array(cfg.face)
    run = SceneRun(width=demo.width)
    receiver = demo.y[:, list(RECEIVER_DOFS)]
    robot = bip.predict(np.zeros(1), GIVER_DOFS)[0]
    reach_end = cfg.lead_s + demo.duration
    release_at = reach_end + cfg.share_s
    back = MinJerkSegment(receiver[-1], receiver[0], release_at, cfg.retreat_s)
    t_end = release_at + cfg.retreat_s + cfg.tail_s
    n_ticks = int(round(t_end / dt)) + 1
    pending: list[Event] = []
    for k in range(n_ticks):
        t = k * dt
        if t < cfg.lead_s:
            person = receiver[0]
        elif t <= reach_end:
            i = min(int(round((t - cfg.lead_s) * RATE_HZ)), demo.t.size - 1)
            if i == 0:
                pending.append(Event(EventKind.ROBOT_REACH_STARTED, t, t,
                                     {"planned_duration": float(1.0 / prior.mean[1])}))
            person = receiver[i]
            bip.step(demo.y[i, obs], dt)
            robot = bip.predict(np.zeros(1), GIVER_DOFS)[0]
            run.robot_wrists.append(robot.copy())
        else:
            person = back.position(t)
        if abs(t - release_at) < 0.5 * dt:
            pending.append(Event(EventKind.ROBOT_RELEASED, t, t))
        takes = t >= reach_end
        share = 0.0 if not takes else (0.5 if t < release_at else 1.0)
        hands = 0.5 * (person[:3] + person[3:])
        obj = hands if t >= release_at else 0.5 * (robot[:3] + robot[3:])
        frame = TrackingFrame.make(t, giver_hand=hands, receiver_hand=obj, giver_face=face,
                                   gripper_closed=takes, load_share=share)
        loop.notify(pending)
        run.events.extend(pending)
        pending = []
        cmd = loop.tick(frame)
        if cmd is not None:
            run.ticks.append(TickRecord(
                t=t, phase=cmd.phase.value, target=cmd.target, head=dict(cmd.head),
                eye_yaw=cmd.eye_yaw, eye_pitch=cmd.eye_pitch,
                target_point=cmd.target_point.copy(), hand=hands.copy(), face=face.copy(),
                events=tuple(e.kind.value for e in cmd.events),
            ))
    return run


def write_scene(run: SceneRun, folder: str | Path) -> dict:
    """``timeline.csv`` and ``timeline.png`` into ``folder``; returns a summary."""
    from gazebot.apps.render.timeline import plot_timeline, write_timeline_csv

    folder = Path(folder)
    csv_path = write_timeline_csv(run.ticks, folder / "timeline.csv")
    png_path = plot_timeline(run.ticks, folder / "timeline.png",
                             title="Robot-giver two-handed reach (BIP) with gaze")
    err = run.grip_width_error()
    phases = [k.phase for k in run.ticks]
    return {
        "timeline_csv": str(csv_path),
        "timeline_png": str(png_path),
        "ticks": len(run.ticks),
        "phases_seen": list(dict.fromkeys(phases)),
        "targets_seen": list(dict.fromkeys(k.target for k in run.ticks)),
        "grip_width_m": run.width,
        "grip_width_error_mean_m": float(err.mean()),
        "grip_width_error_max_m": float(err.max()),
    }
