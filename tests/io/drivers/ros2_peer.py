"""An independent ROS 2 node on the rmw_zenoh wire, built with ``zenoh-ros2-sdk`` (not gazebot):
the other side of the interoperability tests. Run as a script, in its own process (the SDK
keeps one Zenoh session per process); prints one JSON object on the last line of stdout.

``listen``: subscribe, print ``ready`` on a line of its own once the router lists the
subscriptions, list the ROS graph's topics with types and hashes, then record the gaze targets,
head commands, tracked face and hand and phases until the phase is ``done``.

``drive``: publish a recorded handover's tracking topics, gripper, load share and joint states
(paced at ``--speed`` x real time) and record what the engine answers, until the phase is
``done`` and the engine answered the last sample (a gaze target with its stamp).

The SDK reads message definitions from ``--msgdir`` (``<pkg>/msg/<Name>.msg``); it cannot
download them here.
"""

from __future__ import annotations

import argparse
import json
import sys
import threading
import time

TOPICS = {
    "gaze_target": "geometry_msgs/msg/PointStamped",
    "head/command": "trajectory_msgs/msg/JointTrajectory",
    "handover/phase": "gazebot_msgs/msg/HandoverPhase",
}
BODIES = ("giver_hand", "receiver_hand", "giver_face")


def stamp(msg) -> float:
    return msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec


class Record:
    """What the peer's subscriptions received."""

    def __init__(self, ns: str, port: int) -> None:
        from zenoh_ros2_sdk import ROS2Subscriber

        self.lock = threading.Lock()
        self.targets: list = []
        self.heads: list = []
        self.phases: list = []
        self.points: dict = {b: [] for b in BODIES}
        self.hashes: dict = {}
        self.subs = []

        def sub(topic, type_name, fn):
            s = ROS2Subscriber(f"{ns}/{topic}", type_name, fn, node_name="sdk_listener",
                               namespace="/", router_port=port)
            self.hashes[f"{ns}/{topic}"] = s.type_hash
            self.subs.append(s)

        sub("gaze_target", TOPICS["gaze_target"], self.on_target)
        sub("head/command", TOPICS["head/command"], self.on_head)
        sub("handover/phase", TOPICS["handover/phase"], self.on_phase)

    def on_target(self, m) -> None:
        with self.lock:
            self.targets.append([stamp(m), m.point.x, m.point.y, m.point.z, m.header.frame_id])

    def on_head(self, m) -> None:
        p = m.points[0]
        with self.lock:
            self.heads.append({"joint_names": list(m.joint_names),
                               "positions": [float(v) for v in p.positions],
                               "velocities": [float(v) for v in p.velocities],
                               "time_from_start": p.time_from_start.sec
                               + 1e-9 * p.time_from_start.nanosec})

    def on_phase(self, m) -> None:
        with self.lock:
            if not self.phases or self.phases[-1] != m.phase:
                self.phases.append(str(m.phase))

    def done(self) -> bool:
        with self.lock:
            return "done" in self.phases

    def answered(self, t: float) -> bool:
        """Whether a gaze target stamped ``t`` (or later) arrived."""
        with self.lock:
            return any(target[0] >= t for target in self.targets)

    def result(self) -> dict:
        with self.lock:
            return {"targets": self.targets, "heads": self.heads, "phases": self.phases,
                    "points": self.points, "sdk_hashes": self.hashes}


def graph(port: int, ns: str, wait: float) -> dict:
    """``ros2 topic list -t`` and the type hashes, once gazebot's topics are all there."""
    from zenoh_ros2_sdk import get_topic_info, get_topic_names_and_types

    deadline = time.monotonic() + wait
    while True:  # until gazebot publishes every topic we subscribe to
        infos = [get_topic_info(f"{ns}/{t}", router_port=port, timeout=1.0) for t in TOPICS]
        if all(i is not None and i.publisher_count > 0 for i in infos):
            break
        if time.monotonic() > deadline:
            break
        time.sleep(0.2)
    # The union of a few listings, as the ROS 2 daemon's graph builds up: one liveliness query
    # on a busy machine may come back before every router answered.
    topics: dict = {}
    quiet = 0
    while quiet < 3:
        before = {k: set(v) for k, v in topics.items()}
        for name, types in get_topic_names_and_types(router_port=port, timeout=2.0):
            topics.setdefault(name, set()).update(types)
        quiet = quiet + 1 if topics == before else 0
        time.sleep(0.2)
    topics = {k: sorted(v) for k, v in topics.items()}
    out = {}
    # The topics the peer records have publishers while the handover runs: a reply without
    # one came back short (its own subscription answers first).
    published = {f"{ns}/{t}" for t in (*TOPICS, *(f"tracking/{b}" for b in BODIES))}
    for name, types in topics.items():
        for _ in range(10):  # a liveliness query on a busy machine may come back short
            info = get_topic_info(name, router_port=port, timeout=1.0, verbose=True)
            endpoints = (info.publishers + info.subscribers) if info else []
            if endpoints and (name not in published or info.publishers):
                break
        out[name] = {"types": types,
                     "hashes": sorted({e.type_hash for e in endpoints}),
                     "publishers": sorted({e.node_name for e in info.publishers}) if info else []}
    return out


def subscribed(port: int, ns: str, wait: float) -> None:
    """Until the router lists a subscription on each topic the peer records (its own)."""
    from zenoh_ros2_sdk import get_topic_info

    deadline = time.monotonic() + wait
    while time.monotonic() < deadline:
        infos = [get_topic_info(f"{ns}/{t}", router_port=port, timeout=1.0) for t in TOPICS]
        if all(i is not None and i.subscriber_count > 0 for i in infos):
            return
        time.sleep(0.1)
    raise SystemExit(f"the router never listed the peer's subscriptions in {wait} s")


def listen(args) -> dict:
    from zenoh_ros2_sdk import ROS2Subscriber

    rec = Record(args.ns, args.port)
    for body in BODIES:
        def on_point(m, body=body) -> None:
            with rec.lock:
                rec.points[body].append([stamp(m), m.point.x, m.point.y, m.point.z])

        rec.subs.append(ROS2Subscriber(f"{args.ns}/tracking/{body}",
                                       "geometry_msgs/msg/PointStamped", on_point,
                                       node_name="sdk_listener", router_port=args.port))
    subscribed(args.port, args.ns, args.wait)
    print("ready", flush=True)
    topics = graph(args.port, args.ns, args.wait)
    deadline = time.monotonic() + args.duration
    while not rec.done() and time.monotonic() < deadline:
        time.sleep(0.05)
    return {"topics": topics, **rec.result()}


def drive(args) -> dict:
    from zenoh_ros2_sdk import ROS2Publisher, get_message_class

    with open(args.recording) as f:
        ticks = json.load(f)
    rec = Record(args.ns, args.port)
    kw = {"node_name": "sdk_robot", "router_port": args.port}
    pubs = {b: ROS2Publisher(f"{args.ns}/tracking/{b}", "geometry_msgs/msg/PointStamped", **kw)
            for b in BODIES}
    gripper = ROS2Publisher(f"{args.ns}/robot/gripper", "gazebot_msgs/msg/GripperState", **kw)
    share = ROS2Publisher(f"{args.ns}/robot/load_share", "gazebot_msgs/msg/LoadShare", **kw)
    joints = ROS2Publisher("/joint_states", "sensor_msgs/msg/JointState", **kw)
    Header = get_message_class("std_msgs/msg/Header")
    Time = get_message_class("builtin_interfaces/msg/Time")
    Point = get_message_class("geometry_msgs/msg/Point")
    import numpy as np

    topics = graph(args.port, args.ns, args.wait)  # the engine is up: its topics are listed

    def header(t: float, frame: str = ""):
        ns = round(t * 1e9)
        return Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=frame)

    start = time.monotonic()
    t0 = ticks[0]["t"]
    for tick in ticks:
        t = tick["t"]
        delay = start + (t - t0) / args.speed - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        names = sorted(tick["joints"])
        joints.publish(header=header(t), name=names,
                       position=np.array([tick["joints"][n] for n in names], np.float64),
                       velocity=np.zeros(0), effort=np.zeros(0))
        for body in BODIES:
            p = tick[body]
            if p is not None:
                pubs[body].publish(header=header(t, "world"), point=Point(x=p[0], y=p[1], z=p[2]))
        gripper.publish(header=header(t), closed=bool(tick["gripper_closed"]))
        share.publish(header=header(t), share=float(tick["load_share"]))
    # The last sample's answer: its gaze target, stamped with the sample's time (as sent).
    last = round(ticks[-1]["t"] * 1e9) * 1e-9
    deadline = time.monotonic() + args.duration
    while not (rec.done() and rec.answered(last - 1e-9)) and time.monotonic() < deadline:
        time.sleep(0.05)
    return {"topics": topics, **rec.result()}


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=("listen", "drive"))
    p.add_argument("--port", type=int, required=True)
    p.add_argument("--msgdir", required=True)
    p.add_argument("--ns", default="/gazebot")
    p.add_argument("--recording")
    p.add_argument("--speed", type=float, default=1.0)
    p.add_argument("--wait", type=float, default=60.0)
    p.add_argument("--duration", type=float, default=60.0)
    args = p.parse_args()
    from zenoh_ros2_sdk import get_registry

    get_registry(args.msgdir)  # before anything else: the SDK's one registry
    out = listen(args) if args.mode == "listen" else drive(args)
    json.dump(out, sys.stdout)
    sys.stdout.flush()
    import os

    os._exit(0)  # the SDK's session threads would keep the process alive


if __name__ == "__main__":
    raise SystemExit(main())
