"""A ROS 2 publisher built with ``zenoh-ros2-sdk`` (an rmw_zenoh implementation independent of
gazebot), run as a script in its own process: the other side of ``gazebot topic`` tests.

Waits until the router lists a subscription of its topic, then publishes ``--count``
``geometry_msgs/msg/PointStamped`` at ``--rate`` Hz (paced on absolute deadlines), message ``i``
with point ``(i, 2 i, 3 i)`` and its publish time as stamp; prints one JSON object: the
``time.monotonic()`` at which each publish call returned, measured here.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("--port", type=int, required=True)
    p.add_argument("--msgdir", required=True)
    p.add_argument("--topic", required=True)
    p.add_argument("--rate", type=float, required=True)
    p.add_argument("--count", type=int, required=True)
    p.add_argument("--wait", type=float, default=120.0)
    args = p.parse_args()
    from zenoh_ros2_sdk import ROS2Publisher, get_message_class, get_registry, get_topic_info

    get_registry(args.msgdir)  # before anything else: the SDK's one registry
    pub = ROS2Publisher(args.topic, "geometry_msgs/msg/PointStamped", node_name="sdk_talker",
                        router_port=args.port)
    Header = get_message_class("std_msgs/msg/Header")
    Time = get_message_class("builtin_interfaces/msg/Time")
    Point = get_message_class("geometry_msgs/msg/Point")
    deadline = time.monotonic() + args.wait
    while True:
        info = get_topic_info(args.topic, router_port=args.port, timeout=1.0)
        if info is not None and info.subscriber_count > 0:
            break
        if time.monotonic() > deadline:
            raise SystemExit(f"no subscription of {args.topic} in {args.wait} s")
        time.sleep(0.1)
    print(f"subscribed at {time.monotonic():.3f}", file=sys.stderr, flush=True)
    time.sleep(1.0)  # the router lists a subscription before its route is in place
    sent: list[float] = []
    start = time.monotonic()
    for i in range(args.count):
        delay = start + i / args.rate - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        now = time.time_ns()
        pub.publish(header=Header(stamp=Time(sec=now // 10**9, nanosec=now % 10**9),
                                  frame_id="sdk"),
                    point=Point(x=float(i), y=2.0 * i, z=3.0 * i))
        sent.append(time.monotonic())  # handed to Zenoh (the first call declares, slowly)
    json.dump({"sent": sent}, sys.stdout)
    sys.stdout.flush()
    os._exit(0)  # the SDK's session threads would keep the process alive


if __name__ == "__main__":
    raise SystemExit(main())
