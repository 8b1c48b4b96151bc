"""Engine step cost: the full pipeline (phases -> behavior -> IK + gaze shifts) per tracking frame,
against a hand-written peer of the kind labs write today (a distance rule for the phase, fixed
face/hand switch, closed-form atan2 pan/tilt), measured in the same run. Also the runtime loop's
tick (the engine step plus safety checks, blink and vergence distance) against the bare engine
step: what the one loop costs on top."""

from __future__ import annotations

import math

import numpy as np

from benchmarks.common import Result, alternating
from gazebot import GazeEngine
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.core.runtime import GazeLoop


def _hand_written_peer(frames):
    """Face until the hands are within 0.3 m, then the hand; atan2 pan/tilt toward the target."""
    state = {"i": 0}

    def step():
        f = frames[state["i"] % len(frames)]
        state["i"] += 1
        d = float(np.linalg.norm(f.giver_hand - f.receiver_hand))
        target = f.giver_hand if d < 0.3 else f.giver_face
        pan = math.atan2(target[1], target[0])
        tilt = math.atan2(-(target[2] - 1.0), math.hypot(target[0], target[1]))
        return min(max(pan, -0.9), 0.9), tilt

    return step


def run() -> list[Result]:
    recording = generate(seed=3, options=SyntheticOptions(rate=120.0, posture="standing"))
    frames = recording.trajectory.frames()
    results = []
    for robot in ("sawyer", "jaco2"):
        engine = GazeEngine.from_config(robot=robot, behavior="face-hand-face")
        state = {"i": 0}

        def step(engine=engine, state=state):
            i = state["i"]
            if i % len(frames) == 0:
                engine.reset()
            engine.step(frames[i % len(frames)])
            state["i"] = i + 1

        n = len(frames)
        peer_step = _hand_written_peer(frames)
        # Whole recordings (the step at frame 0 resets the engine), ours and the peer's in
        # alternating rounds: wall medians and the least CPU time of each.
        ours, peer, cpu_ours, cpu_peer = (
            x * 1e6 for x in alternating(step, peer_step, rounds=15, number=n)
        )
        results.append(
            Result(
                f"engine.step, {robot}, face-hand-face, 120 Hz handover",
                ours,
                peer,
                "us/step",
                "hand-written distance rule + atan2",
                note=f"CPU time {cpu_ours:.0f} us/step, peer {cpu_peer:.2g} us "
                f"(x{cpu_peer / cpu_ours:.3f})",
            )
        )
        loop = GazeLoop(GazeEngine.from_config(robot=robot, behavior="face-hand-face"))
        bare = GazeEngine.from_config(robot=robot, behavior="face-hand-face")
        tick_state = {"i": 0}
        step_state = {"i": 0}

        def tick(loop=loop, state=tick_state):
            i = state["i"]
            if i % len(frames) == 0:
                loop.reset()
            f = frames[i % len(frames)]
            loop.tick(f)
            state["i"] = i + 1

        def bare_step(engine=bare, state=step_state):
            i = state["i"]
            if i % len(frames) == 0:
                engine.reset()
            engine.step(frames[i % len(frames)])
            state["i"] = i + 1

        ours, peer, cpu_ours, cpu_peer = (
            x * 1e6 for x in alternating(tick, bare_step, rounds=15, number=n)
        )
        results.append(
            Result(
                f"GazeLoop.tick, {robot}: engine + safety + blink + vergence",
                ours,
                peer,
                "us/tick",
                "GazeEngine.step alone",
                note=f"the loop adds {ours - peer:.0f} us; CPU time {cpu_ours:.0f} vs "
                f"{cpu_peer:.0f} us/tick: adds {cpu_ours - cpu_peer:.0f} us",
            )
        )
    return results
