"""Embed the gaze engine in a robot stack: feed it tracking frames, send its commands on.

Here the "robot stack" is a loop over a recording (any format `gazebot phases` reads: CSV,
C3D, ROS bag, a folder of pose CSVs); a real stack calls `engine.step` from its tracking
callback instead and forwards `cmd.head` to the neck controller and `cmd.eye_yaw` /
`cmd.eye_pitch` to the face display.

    python examples/embed_engine.py recording.csv --robot jaco2 --behavior hand-face
    python examples/embed_engine.py handover_sample --rate 120 \
        --giver-hand giver_RHand --receiver-hand taker_RHand --giver-face giver_head
    python examples/embed_engine.py            # a synthetic handover, generated on the fly
"""

from __future__ import annotations

import argparse
import math

from gazebot import Event, EventKind, GazeEngine
from gazebot.core.phases import load_phase_config
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.io.recordings import PointNames, load_recording


def main(argv: list[str] | None = None) -> list[str]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv", nargs="?", help="recording (default: a synthetic handover)")
    parser.add_argument("--robot", default="sawyer")
    parser.add_argument("--behavior", default="face-hand-face")
    parser.add_argument("--method", default=None, help="phase method (default: gazebot)")
    parser.add_argument("--giver-hand", default=None)
    parser.add_argument("--receiver-hand", default=None)
    parser.add_argument("--giver-face", default=None)
    parser.add_argument("--rate", type=float, default=None, help="pose-folder rate (Hz)")
    args = parser.parse_args(argv)

    if args.csv:
        names = PointNames(args.giver_hand, args.receiver_hand, args.giver_face)
        trajectory = load_recording(args.csv, names, rate=args.rate).trajectory
    else:
        trajectory = generate(seed=1, options=SyntheticOptions(rate=120.0)).trajectory
    phases = load_phase_config()
    if args.method:
        phases = phases.model_copy(update={"method": args.method})
    engine = GazeEngine.from_config(robot=args.robot, behavior=args.behavior, phases=phases)

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
