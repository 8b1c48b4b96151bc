"""The one runtime loop in process and on the bus: one recorded handover gives the same command
stream through ``GazeLoop`` directly and through the engine node over Zenoh."""

from __future__ import annotations

import threading
import time

import pytest

from gazebot.runtime import GazeLoop


@pytest.fixture(scope="module")
def recorded_handover():
    """One simulated Sawyer handover as a robot would report it, tick by tick: the tracking
    sample, the robot controller's events and the measured joints (120 Hz)."""
    from gazebot.sim import HandoverSimulation

    ticks = []
    with HandoverSimulation("sawyer", "default", seed=2) as sim:
        done_at = None
        while sim.t < 15.0:
            sim.step(1 / 120)
            ticks.append((sim.tracking(), sim.robot_events(), dict(sim.joint_state())))
            if done_at is None and sim.done:
                done_at = sim.t
            # the phase detector confirms the end from the tracking about 2 s later
            if done_at is not None and sim.t > done_at + 3.0:
                break
    assert done_at is not None, "the recorded handover did not finish"
    return ticks


def _key(head, yaw, pitch, blink, distance, target, phase):
    return (dict(head), yaw, pitch, blink, distance, target, phase)


def in_process(ticks):
    loop = GazeLoop.from_config("sawyer", "face-hand-face", seed=5)
    out = []
    for frame, events, joints in ticks:
        loop.notify(events)
        c = loop.tick(frame, joints=joints)
        out.append(_key(c.head, c.eye_yaw, c.eye_pitch, c.blink, c.distance, c.target,
                        c.phase.value))
    return out


@pytest.mark.zenoh
def test_recorded_handover_gives_the_same_commands_in_process_and_over_zenoh(
    recorded_handover, bus
):
    from gazebot.drivers.engine_node import EngineNode, EngineNodeConfig
    from gazebot.drivers.payloads import EyeStateMsg, HeadCommandMsg
    from gazebot.drivers.zenoh_driver import ZenohRobotDriver
    from gazebot.drivers.zenoh_robot import ZenohRobotEndpoint

    expected = in_process(recorded_handover)
    phases = {p for *_, p in expected}
    assert {"reach", "transfer", "retreat", "done"} <= phases
    assert any(k[3] > 0.5 for k in expected)  # the stream has blinks

    ep = ZenohRobotEndpoint(bus.listener(), bus.config().keys, "sim")
    bus.closers.append(ep.close)
    drv = ZenohRobotDriver(bus.connector(), bus.config().keys, "engine")
    heads: list[HeadCommandMsg] = []
    eyes: list[EyeStateMsg] = []
    ep.session.declare_subscriber(
        ep.keys.head_command, lambda s: heads.append(HeadCommandMsg.decode(s.payload.to_bytes())))
    ep.session.declare_subscriber(
        ep.keys.eyes, lambda s: eyes.append(EyeStateMsg.decode(s.payload.to_bytes())))
    # No silence ticks (a loaded machine may pause between samples) and no resync: the stream
    # must be the samples' answers alone, from the same initial state as in process.
    cfg = EngineNodeConfig(silence_after=1e6, resync=False)
    node = EngineNode(GazeLoop.from_config("sawyer", "face-hand-face", seed=5), drv, cfg)
    stop = threading.Event()
    th = threading.Thread(target=node.run, kwargs={"stop": stop}, daemon=True)

    def close():
        stop.set()
        th.join(timeout=10)
        drv.close()

    bus.closers.append(close)
    deadline = time.monotonic() + 30
    while not (ep.peers().get("engine") and drv.peers().get("sim")):
        assert time.monotonic() < deadline, "the two nodes never saw each other"
        time.sleep(0.01)
    th.start()
    assert node.ready.wait(30)
    def wait(pred, what):
        deadline = time.monotonic() + 30  # generous: a busy machine is slow
        while not pred():
            assert time.monotonic() < deadline, what
            time.sleep(0.0002)

    seen_events = 0
    for i, (frame, events, joints) in enumerate(recorded_handover):
        # Zenoh keeps the order within a key, not across keys: the engine must have the robot's
        # events and joints of this tick before its sample, as in process.
        for event in events:
            ep.publish_robot_event(event)
        seen_events += len(events)
        n, t = seen_events, frame.t
        wait(lambda n=n: len([m for m in drv.history() if m.source == "sim"]) >= n,
             f"robot events of sample {i}")
        ep.publish_joint_state(t, joints)
        wait(lambda t=t: (js := drv.joint_state()) is not None and js.t == t,
             f"joint state of sample {i}")
        msg = ep.publish_tracking(frame)
        wait(lambda i=i: len(heads) > i and len(eyes) > i, f"no answer to sample {i}")
        assert heads[i].answers == msg.seq
    got = [
        _key(h.head, e.yaw, e.pitch, e.blink, e.distance, h.target, h.phase)
        for h, e in zip(heads, eyes, strict=True)
    ]
    assert len(got) == len(expected)
    for i, (a, b) in enumerate(zip(got, expected, strict=True)):
        assert a == b, f"tick {i}: over Zenoh {a} != in process {b}"
