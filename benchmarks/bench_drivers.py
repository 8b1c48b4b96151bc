"""Bus latency and simulator speed.

* tracking-in to head-command-out: a tracking sample (its ROS 2 messages on the rmw_zenoh wire:
  three ``PointStamped``, ``GripperState``, ``LoadShare``, CDR with rmw_zenoh's attachment)
  crosses Zenoh to a real engine node (``GazeEngine`` sawyer / face-hand-face), which answers with
  a ``JointTrajectory`` head command back across Zenoh. Peer: a raw Zenoh echo between the same
  two sessions of the same bytes (the same five payloads on five keys; when all five arrived, a
  payload of the head command's size back), measured interleaved with ours in the same run.
  Samples come from a simulated handover, so the engine's phases and behavior do their real
  work.
* the simulator node's real-time factor without rendering (tracking and joint states published
  on the bus, no pacing) against the bare simulation stepping loop.
"""

from __future__ import annotations

import os
import socket
import statistics
import threading
import time

from benchmarks.common import Result

N_SAMPLES = int(os.environ.get("GAZEBOT_BENCH_DRIVERS_N", "600"))
#: How long (s) a round trip is waited for. An unanswered sample counts at this value in the
#: percentiles (leaving it out would flatter the tail) and is reported.
ANSWER_TIMEOUT = 1.0
SIM_SECONDS = 6.0


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _percentile(xs: list[float], q: float) -> float:
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(q * (len(xs) - 1))))]


def _record_frames(seconds: float) -> list:
    from gazebot.apps.sim import HandoverSimulation

    with HandoverSimulation("sawyer", "default", seed=0) as sim:
        frames = []
        while sim.t < seconds:
            sim.step(1 / 120)
            frames.append(sim.tracking())
    return frames


def _latency() -> list[Result]:
    from gazebot.core.engine import GazeEngine
    from gazebot.core.runtime import GazeLoop
    from gazebot.io.drivers.engine_node import EngineNode, EngineNodeConfig
    from gazebot.io.drivers.rmw.names import Names
    from gazebot.io.drivers.session import EPHEMERAL_ENDPOINT, BusConfig, open_session
    from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
    from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint
    from gazebot.io.ros2 import convert, topics
    from gazebot.io.ros2.values import JointGoal

    frames = _record_frames(N_SAMPLES / 120)
    names = Names("/bench")
    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    robot = ZenohRobotEndpoint(open_session(BusConfig(names, listen=(endpoint,))), names,
                               "sim", owns_session=True)
    engine_session = open_session(
        BusConfig(names, listen=(EPHEMERAL_ENDPOINT,), connect=(endpoint,)))
    driver = ZenohRobotDriver(engine_session, names, "engine")
    # Every answer is a sample's: no silence ticks, so the n-th head command answers sample n.
    node = EngineNode(GazeLoop(GazeEngine.from_config("sawyer", "face-hand-face")), driver,
                      EngineNodeConfig(silence_after=1e3, resync=False))
    stop = threading.Event()
    engine_thread = threading.Thread(target=node.run, kwargs={"stop": stop}, daemon=True)
    entities = []
    try:
        answered = threading.Event()
        state = {"heads": 0, "want": 0, "pings": 0, "expect": 0, "at": 0.0}
        head_key = robot.ros.names.key(
            names.resolve(topics.HEAD_COMMAND.name),
            *(lambda c: (c.info.dds_name, c.info.hash))(robot.ros.codec(topics.HEAD_COMMAND.type)))

        def on_head(sample) -> None:
            state["heads"] += 1
            if state["heads"] == state["want"]:
                state["at"] = time.perf_counter()
                answered.set()

        def on_pong(sample) -> None:
            state["at"] = time.perf_counter()
            answered.set()

        pubs = {body: robot._point_pubs[body] for body in convert.BODIES}
        parts = [*pubs.values(), robot._gripper_pub, robot._share_pub]
        # Raw echo in the engine's session: same sessions, same links, same payloads.
        echo_pub = engine_session.declare_publisher("bench/raw/pong")
        pong = {"size": 0}

        def on_ping(sample) -> None:
            state["pings"] += 1
            if state["pings"] == state["expect"]:
                state["pings"] = 0
                echo_pub.put(bytes(pong["size"]))

        entities += [
            echo_pub,
            engine_session.declare_subscriber("bench/raw/ping/*", on_ping),
            robot.session.declare_subscriber(head_key, on_head),
            robot.session.declare_subscriber("bench/raw/pong", on_pong),
        ]
        ping_pubs = [robot.session.declare_publisher(f"bench/raw/ping/{i}")
                     for i in range(len(parts))]
        entities += ping_pubs
        deadline = time.monotonic() + 5
        while not driver.peers().get("sim") and time.monotonic() < deadline:
            time.sleep(0.01)
        engine_thread.start()
        node.ready.wait(5)
        pong["size"] = len(robot.ros.codec(topics.HEAD_COMMAND.type).encode(
            convert.joint_trajectory(JointGoal.head_of(
                GazeEngine.from_config("sawyer", "face-hand-face").step(frames[0])))))

        ours: list[float] = []
        raw: list[float] = []
        unanswered = {"ours": 0, "raw": 0}
        sizes = []
        base = names.base_frame
        for seq, frame in enumerate(frames):
            tracked = convert.tracking_points(frame)  # an untracked body is not sent
            sample = [(pubs[b], pubs[b].codec.encode(convert.point_stamped(frame.t, p, base)))
                      for b, p in tracked.items()]
            sample.append((robot._gripper_pub, robot._gripper_pub.codec.encode(
                convert.gripper_state(frame.t, bool(frame.gripper_closed)))))
            sample.append((robot._share_pub, robot._share_pub.codec.encode(
                convert.load_share(frame.t, float(frame.load_share)))))
            sizes.append(sum(len(data) for _, data in sample))
            state["expect"] = len(sample)
            for kind in ("ours", "raw"):  # interleaved: both see the same conditions
                answered.clear()
                state["want"] = seq + 1
                t0 = time.perf_counter()
                if kind == "ours":
                    for pub, data in sample:
                        pub.publish_raw(data)
                else:
                    for pub, (_, data) in zip(ping_pubs, sample, strict=False):
                        pub.put(data)
                if answered.wait(ANSWER_TIMEOUT):
                    (ours if kind == "ours" else raw).append(state["at"] - t0)
                    continue
                (ours if kind == "ours" else raw).append(ANSWER_TIMEOUT)
                unanswered[kind] += 1
                if kind == "ours":
                    state["heads"] = state["want"]  # a lost answer: count it as given
            time.sleep(0.001)  # let the engine's loop settle between samples
    finally:
        stop.set()
        if engine_thread.is_alive():
            engine_thread.join(timeout=5)
        for e in entities:
            e.undeclare()
        driver.close()
        engine_session.close()
        robot.close()

    size = int(statistics.median(sizes))
    note = (f"{len(ours)} samples, 5 CDR messages = {size} B in (median), {pong['size']} B back, "
            f"round trip A->B->A; unanswered in {ANSWER_TIMEOUT:g} s (counted at "
            f"{ANSWER_TIMEOUT:g} s): {unanswered['ours']} ours, {unanswered['raw']} echo")
    ms = 1e3
    return [
        Result("tracking in -> head command out, p50", statistics.median(ours) * ms,
               statistics.median(raw) * ms, "ms", "raw Zenoh echo p50", note=note),
        Result("tracking in -> head command out, p99", _percentile(ours, 0.99) * ms,
               _percentile(raw, 0.99) * ms, "ms", "raw Zenoh echo p99", note=note),
    ]


def _real_time_factor(repeat: int = 3) -> list[Result]:
    from gazebot.apps.sim import HandoverSimulation
    from gazebot.io.drivers.session import BusConfig
    from gazebot.io.drivers.sim_node import SimNode, SimNodeConfig
    from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint

    def bare() -> float:
        with HandoverSimulation("sawyer", "default", seed=0) as sim:
            t0 = time.perf_counter()
            while sim.t < SIM_SECONDS:
                sim.step(1 / 120)
                sim.tracking()
                sim.robot_events()
            return sim.t / (time.perf_counter() - t0)

    def on_bus(endpoint: ZenohRobotEndpoint) -> float:
        with HandoverSimulation("sawyer", "default", seed=0) as sim:
            return SimNode(sim, endpoint, SimNodeConfig(speed=float("inf"))).run(SIM_SECONDS)

    from gazebot.io.drivers.rmw.names import Names

    endpoint = ZenohRobotEndpoint.open(
        BusConfig(Names("/benchrtf"), listen=(f"tcp/127.0.0.1:{_free_port()}",)), "sim")
    ours, peer = [], []
    try:
        bare()  # warm-up (imports, MuJoCo model compilation caches)
        for _ in range(repeat):  # alternated, so both see the same machine load
            peer.append(bare())
            ours.append(on_bus(endpoint))
    finally:
        endpoint.close()
    return [
        Result("sim node real-time factor (no rendering, 120 Hz tracking on the bus)",
               statistics.median(ours), statistics.median(peer), "x real time",
               "bare HandoverSimulation.step loop", higher_is_better=True,
               note=f"median of {repeat} x {SIM_SECONDS:g} s simulated handover, sawyer"),
    ]


def run() -> list[Result]:
    return _latency() + _real_time_factor()


if __name__ == "__main__":
    from benchmarks.common import print_results

    print_results(run())
