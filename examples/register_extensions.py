"""Extending gazebot from your own code: a phase method and a reach controller of your own, each
one class plus one registration line, then used by name like the built-ins.

    python examples/register_extensions.py

- ``closest-approach`` (phase method): the reach is the hands closing in to their closest
  approach, the transfer the time they stay within ``HOLD_M`` of it, the retreat the giver's
  hand going back out to where it started. Offline (``segment``) and online (the engine's
  detector, with ``method: closest-approach``), like any method.
- ``straight`` (reach controller): straight to the hand at a constant speed.
"""

from __future__ import annotations

import numpy as np

from gazebot.apps.controllers import CONTROLLERS, ReachController, ReachObservation, VelocityPlan
from gazebot.apps.controllers.base import integrate
from gazebot.core.phases import PhaseConfig, Segment, Trajectory, segment
from gazebot.core.phases.methods import PHASE_METHODS, Segmenter
from gazebot.core.types import Phase

HOLD_M = 0.03  # the hands are "together" within this of their closest approach (m)
SETTLE_S = 0.2  # online: the closest approach is this old before it counts (s)


class ClosestApproach(Segmenter):
    """Reach, transfer and retreat around the hands' closest approach (one handover)."""

    name = "closest-approach"

    def segment_sorted(self, trajectory: Trajectory, partial: bool = False) -> list[Segment]:
        t = trajectory.t
        d = np.linalg.norm(trajectory.giver_hand - trajectory.receiver_hand, axis=1)
        ok = np.flatnonzero(np.isfinite(d))
        if ok.size < 3 or d[ok[0]] - np.nanmin(d) < 2 * HOLD_M:
            return []  # the hands never closed in: no handover (yet)
        together = ok[d[ok] <= np.nanmin(d) + HOLD_M]
        first, last = together[0], together[-1]
        # The reach starts where the hands began closing in (HOLD_M below where they started).
        start = ok[(ok < first) & (d[ok] <= d[ok[0]] - HOLD_M)][0]
        closest = ok[int(np.argmin(d[ok]))]
        if partial and t[ok[-1]] - t[closest] < SETTLE_S:
            # Online: the hands may still be closing in; only the reach is known.
            return [Segment(Phase.REACH, t[start], t[ok[-1]], open=True)]
        back = ok[(ok > last) & (d[ok] >= d[start] - HOLD_M)]
        if partial and last == ok[-1]:
            # Online: the hands are still together; the transfer is open.
            return [Segment(Phase.REACH, t[start], t[first]),
                    Segment(Phase.TRANSFER, t[first], t[ok[-1]], open=True)]
        end = t[back[0]] if back.size else t[ok[-1]]
        return [
            Segment(Phase.REACH, t[start], t[first]),
            Segment(Phase.TRANSFER, t[first], t[last]),
            Segment(Phase.RETREAT, t[last], end, open=not back.size),
        ]


class Straight(ReachController):
    """Straight to the hand at the speed cap."""

    name = "straight"

    def plan(self, obs: ReachObservation) -> VelocityPlan:
        to_hand = obs.hand - np.asarray(obs.x, float)
        u = self.cap(to_hand / self.dt)[None, :]
        return VelocityPlan(obs.t, self.dt, u, integrate(obs.x, u, self.dt), True, 0.0)


def register() -> None:
    """The two registration lines (``replace``: running the example twice is fine)."""
    PHASE_METHODS.register(ClosestApproach.name, ClosestApproach, "closest approach (example)",
                           replace=True)
    CONTROLLERS.register(Straight.name, Straight, "straight at the speed cap (example)",
                         replace=True)


def main() -> list[str]:
    from gazebot import GazeEngine
    from gazebot.apps.controllers import make_controller
    from gazebot.core.phases.synthetic import SyntheticOptions, generate

    register()
    lines = []
    recording = generate(seed=1, options=SyntheticOptions(rate=120.0))
    truth = recording.truth[0]
    lines.append(f"truth    reach {truth.reach_start:.2f} s, transfer {truth.transfer_start:.2f} s")
    config = PhaseConfig(method="closest-approach")  # validated against the registry
    for seg in segment(recording.trajectory, config)[:3]:
        lines.append(f"{seg.phase.value:8s} {seg.start:5.2f} .. {seg.end:5.2f} s")
    # The engine's online detector runs it too.
    engine = GazeEngine.from_config("sawyer", "face-hand-face", phases=config)
    for frame in recording.trajectory.frames():
        for event in engine.step(frame).events:
            lines.append(f"online   {event.kind.value} at {event.t:.2f} s")
    controller = make_controller("straight")
    obs = ReachObservation(t=0.0, x=np.zeros(3), hand=np.array([0.6, 0.0, 0.0]))
    lines.append(f"straight: {controller.plan(obs).command.round(3).tolist()} m/s")
    for line in lines:
        print(line)
    return lines


if __name__ == "__main__":
    main()
