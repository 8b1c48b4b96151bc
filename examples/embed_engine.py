"""Embed the gaze engine in a robot stack: feed it tracking frames, send its commands on.

Here the "robot stack" is a loop over a recorded trajectory CSV (the format `gazebot phases`
reads); a real stack calls `engine.step` from its tracking callback instead and forwards
`cmd.head` to the neck controller and `cmd.eye_yaw` / `cmd.eye_pitch` to the face display.

    python examples/embed_engine.py recording.csv --robot jaco2 --behavior hand-face
    python examples/embed_engine.py            # a synthetic handover, generated on the fly
"""

from __future__ import annotations

import argparse
import math

from gazebot import Event, EventKind, GazeEngine
from gazebot.phases import load_trajectory_csv
from gazebot.phases.synthetic import SyntheticOptions, generate


def main(argv: list[str] | None = None) -> list[str]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv", nargs="?", help="trajectory CSV (default: a synthetic handover)")
    parser.add_argument("--robot", default="sawyer")
    parser.add_argument("--behavior", default="face-hand-face")
    args = parser.parse_args(argv)

    if args.csv:
        trajectory = load_trajectory_csv(args.csv)
    else:
        trajectory = generate(seed=1, options=SyntheticOptions(rate=120.0)).trajectory
    engine = GazeEngine.from_config(robot=args.robot, behavior=args.behavior)

    lines = []
    last_target = None
    for frame in trajectory.iter_frames():
        cmd = engine.step(frame)
        for event in cmd.events:
            lines.append(f"{event.t:6.2f} s  {event.kind.value}")
        if cmd.target != last_target:
            head = ", ".join(f"{j}={math.degrees(q):+.1f} deg" for j, q in cmd.head.items())
            lines.append(f"{cmd.t:6.2f} s  look at {cmd.target:<5} ({head})")
            last_target = cmd.target
        # A robot controller reports its own motions, e.g. when it starts to reach:
        if cmd.events and cmd.events[0].kind is EventKind.REACH_STARTED:
            engine.notify(Event(EventKind.ROBOT_REACH_STARTED, cmd.t, cmd.t,
                                {"planned_duration": 1.2}))
    print("\n".join(lines))
    return lines


if __name__ == "__main__":
    main()
