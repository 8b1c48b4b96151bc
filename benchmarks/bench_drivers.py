"""Bus latency and simulator speed.

* tracking-in to head-command-out: a tracking sample published on ``gazebot/<id>/tracking``
  crosses Zenoh to a real engine node (``GazeEngine`` sawyer / face-hand-face), which answers with
  a head command back across Zenoh. Peer: a raw Zenoh echo between the same two sessions with a
  payload of the same size (publish -> subscriber -> re-publish -> subscriber), measured
  interleaved with ours in the same run. Samples come from a simulated handover, so the engine's
  phases and behavior do their real work.
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
SIM_SECONDS = 6.0


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _percentile(xs: list[float], q: float) -> float:
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(q * (len(xs) - 1))))]


def _record_frames(seconds: float) -> list:
    from gazebot.sim import HandoverSimulation

    with HandoverSimulation("sawyer", "default", seed=0) as sim:
        frames = []
        while sim.t < seconds:
            sim.step(1 / 120)
            frames.append(sim.tracking())
    return frames


def _latency() -> list[Result]:
    from gazebot.drivers.engine_node import EngineNode
    from gazebot.drivers.payloads import HeadCommandMsg, TrackingMsg
    from gazebot.drivers.session import EPHEMERAL_ENDPOINT, BusConfig, open_session
    from gazebot.drivers.zenoh_driver import ZenohRobotDriver
    from gazebot.engine import GazeEngine
    from gazebot.runtime import GazeLoop

    frames = _record_frames(N_SAMPLES / 120)
    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    robot = open_session(BusConfig("bench", listen=(endpoint,)))
    engine_session = open_session(
        BusConfig("bench", listen=(EPHEMERAL_ENDPOINT,), connect=(endpoint,)))
    driver = ZenohRobotDriver(engine_session, BusConfig("bench").keys, "engine")
    keys = driver.keys
    node = EngineNode(GazeLoop(GazeEngine.from_config("sawyer", "face-hand-face")), driver)
    stop = threading.Event()
    engine_thread = threading.Thread(target=node.run, kwargs={"stop": stop}, daemon=True)
    entities = []
    try:
        answered = threading.Event()
        answer: dict[str, float] = {}

        def on_head(sample) -> None:
            msg = HeadCommandMsg.decode(sample.payload.to_bytes())
            if msg.answers == answer.get("want"):
                answer["at"] = time.perf_counter()
                answered.set()

        def on_pong(sample) -> None:
            answer["at"] = time.perf_counter()
            answered.set()

        # Raw echo in the engine's session: same sessions, same links, same payload size.
        echo_pub = engine_session.declare_publisher(f"{keys.root}/bench/pong")
        entities += [
            echo_pub,
            engine_session.declare_subscriber(
                f"{keys.root}/bench/ping", lambda s: echo_pub.put(s.payload.to_bytes())),
            robot.declare_subscriber(keys.head_command, on_head),
            robot.declare_subscriber(f"{keys.root}/bench/pong", on_pong),
        ]
        tracking_pub = robot.declare_publisher(keys.tracking)
        ping_pub = robot.declare_publisher(f"{keys.root}/bench/ping")
        entities += [tracking_pub, ping_pub]
        deadline = time.monotonic() + 5
        while not driver.peers() and time.monotonic() < deadline:
            time.sleep(0.01)
        engine_thread.start()
        node.ready.wait(5)

        ours: list[float] = []
        raw: list[float] = []
        sizes = []
        for seq, frame in enumerate(frames):
            payload = TrackingMsg.from_frame(frame, seq, time.time()).encode()
            sizes.append(len(payload))
            for kind in ("ours", "raw"):  # interleaved: both see the same conditions
                answered.clear()
                answer["want"] = seq
                t0 = time.perf_counter()
                if kind == "ours":
                    tracking_pub.put(payload)
                else:
                    ping_pub.put(payload)
                if answered.wait(1.0):
                    (ours if kind == "ours" else raw).append(answer["at"] - t0)
            time.sleep(0.001)  # let the engine's loop settle between samples
        lost = len(frames) - len(ours)
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
    note = f"{len(ours)} samples, {size} B JSON, round trip A->B->A, {lost} unanswered"
    ms = 1e3
    return [
        Result("tracking in -> head command out, p50", statistics.median(ours) * ms,
               statistics.median(raw) * ms, "ms", "raw Zenoh echo p50", note=note),
        Result("tracking in -> head command out, p99", _percentile(ours, 0.99) * ms,
               _percentile(raw, 0.99) * ms, "ms", "raw Zenoh echo p99", note=note),
    ]


def _real_time_factor(repeat: int = 3) -> list[Result]:
    from gazebot.drivers.session import BusConfig
    from gazebot.drivers.sim_node import SimNode, SimNodeConfig
    from gazebot.drivers.zenoh_robot import ZenohRobotEndpoint
    from gazebot.sim import HandoverSimulation

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

    endpoint = ZenohRobotEndpoint.open(
        BusConfig("benchrtf", listen=(f"tcp/127.0.0.1:{_free_port()}",)), "sim")
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
