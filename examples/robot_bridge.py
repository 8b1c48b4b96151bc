"""A robot bridge on the Zenoh bus: what a real robot's driver does to be driven by `gazebot run`.

It publishes tracking (from your motion capture) and joint states as ROS 2 messages on the
rmw_zenoh wire (``/gazebot/tracking/*`` PointStamped, ``/joint_states``), and applies the head
commands (``/gazebot/head/command``, JointTrajectory) the engine sends. A ROS 2 robot running
rmw_zenoh needs no bridge at all: its own nodes publish and subscribe to these topics.

Here the "robot" is a stand-in that applies head goals instantly and the "motion capture"
replays a synthetic handover; swap both for your hardware interfaces.

The endpoint obeys only the engine that owns the robot (its ownership claim, its live publisher,
its GID in each command's attachment); anything else is dropped and counted (docs/bus.md, "What
the robot trusts"). For a lab, ``gazebot bus init DIR`` makes certificates and configurations:
run this bridge with ``--zenoh-config DIR/robot.json5 --listen tls/HOST:7447``.

Terminal 1:  python examples/robot_bridge.py --duration 10
Terminal 2:  gazebot run --robot sawyer --behavior face-hand-face --duration 10
"""

from __future__ import annotations

import argparse
import time

from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.io.drivers import BusConfig, Names, ZenohRobotEndpoint


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--namespace", default="/gazebot", help="ROS namespace of the topics")
    parser.add_argument("--listen", default="tcp/127.0.0.1:7447")
    parser.add_argument("--duration", type=float, default=10.0, help="wall seconds")
    parser.add_argument("--zenoh-config", default=None, metavar="FILE",
                        help="Zenoh JSON5 configuration (TLS, authentication), as gazebot's nodes")
    args = parser.parse_args(argv)

    frames = generate(seed=2, options=SyntheticOptions(rate=120.0)).trajectory.frames()
    head = {"head_pan": 0.0}
    applied = 0
    bus = BusConfig(names=Names(args.namespace), listen=(args.listen,),
                    config_file=args.zenoh_config)
    robot = ZenohRobotEndpoint.open(bus, node="sim")
    try:
        start = time.monotonic()
        for i, frame in enumerate(frames):
            if time.monotonic() - start > args.duration:
                break
            robot.publish_tracking(frame)
            robot.publish_joint_state(frame.t, head)
            cmd = robot.head.take()
            if cmd is not None:  # your neck controller goes here
                head.update(cmd.positions)
                applied += 1
            if i % 60 == 0:  # a heartbeat every 0.5 s tells the engine the robot is alive
                robot.heartbeat()
            time.sleep(max(0.0, frame.t - frames[0].t - (time.monotonic() - start)))
    finally:
        robot.close()
    dropped = sum(robot.unidentified().values())
    print(f"applied {applied} head commands, dropped {dropped} from no identified owner")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
