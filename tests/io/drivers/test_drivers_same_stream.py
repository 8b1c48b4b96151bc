"""The one runtime loop in process and on the bus: one recorded handover gives the same command
stream through ``GazeLoop`` directly and through the engine node over Zenoh (ROS 2 messages on
the rmw_zenoh wire).

The wire carries times as ``builtin_interfaces/Time`` (whole nanoseconds), so the in-process
reference runs on the same times rounded to the nanosecond: the same input, bit for bit."""

from __future__ import annotations

import dataclasses
import threading
import time

import pytest
from drivers_fakes import Recorder

from gazebot.core.runtime import GazeLoop
from gazebot.core.types import Event
from gazebot.io.ros2 import convert, topics


def on_wire(t: float) -> float:
    """``t`` as it comes off the wire."""
    return convert.from_time(convert.to_time(t))


def wire_event(e: Event) -> Event:
    return dataclasses.replace(e, t=on_wire(e.t), detected_at=on_wire(e.detected_at))


@pytest.fixture(scope="module")
def recorded_handover():
    """One simulated Sawyer handover as a robot would report it, tick by tick: the tracking
    sample, the robot controller's events and the measured joints (120 Hz)."""
    from gazebot.apps.sim import HandoverSimulation

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


def _key(head, yaw, pitch, blink, distance, target_point):
    return (dict(head), yaw, pitch, blink, distance, target_point)


def in_process(ticks):
    loop = GazeLoop.from_config("sawyer", "face-hand-face", seed=5)
    out, phases = [], []
    for frame, events, joints in ticks:
        loop.notify([wire_event(e) for e in events])
        t = on_wire(frame.t)
        c = loop.tick(dataclasses.replace(frame, t=t), joints=joints)
        point = tuple(float(v) for v in c.target_point)
        out.append(_key(c.head, c.eye_yaw, c.eye_pitch, c.blink, c.distance, point))
        if not phases or phases[-1] != c.phase.value:
            phases.append(c.phase.value)
    return out, phases


@pytest.mark.zenoh
def test_recorded_handover_gives_the_same_commands_in_process_and_over_zenoh(
    recorded_handover, bus
):
    from gazebot.io.drivers.engine_node import EngineNode, EngineNodeConfig
    from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
    from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint

    expected, expected_phases = in_process(recorded_handover)
    assert {"reach", "transfer", "retreat", "done"} <= set(expected_phases)
    assert any(k[3] > 0.5 for k in expected)  # the stream has blinks

    ep = ZenohRobotEndpoint(bus.listener(), bus.names, "sim")
    bus.closers.append(ep.close)
    # Samples complete by their parts alone: no wall-clock idle flush on a stalled machine.
    drv = ZenohRobotDriver(bus.connector(), bus.names, "engine", assemble_idle=1e6)
    heads = Recorder(ep, topics.HEAD_COMMAND, lambda m: convert.trajectory_goal(m).positions)
    eyes = Recorder(ep, topics.EYES, convert.eyes_of)
    targets = Recorder(ep, topics.GAZE_TARGET, convert.point_of)
    phases = Recorder(ep, topics.PHASE, convert.phase_of)
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
    # the robot obeys the engine only once it has seen the engine's claim (made at ready)
    deadline = time.monotonic() + 30
    while ep.owners.owner() != drv._ownership.claim:
        assert time.monotonic() < deadline, "the robot never saw the engine's claim"
        time.sleep(0.01)

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
        n, t = seen_events, on_wire(frame.t)
        wait(lambda n=n: len([m for m in drv.history() if m.source == "sim"]) >= n,
             f"robot events of sample {i}")
        ep.publish_joint_state(frame.t, joints)
        wait(lambda t=t: (js := drv.joint_state()) is not None and js.t == t,
             f"joint state of sample {i}")
        ep.publish_tracking(frame)
        wait(lambda i=i: len(heads.msgs) > i and len(eyes.msgs) > i and len(targets.msgs) > i,
             f"no answer to sample {i}")
        assert eyes.msgs[i].t == t and targets.msgs[i][0] == t
    got = [
        _key(h, e.yaw, e.pitch, e.blink, e.distance, tuple(float(v) for v in p))
        for h, e, (_, p) in zip(heads.msgs, eyes.msgs, targets.msgs, strict=True)
    ]
    assert len(got) == len(expected)
    for i, (a, b) in enumerate(zip(got, expected, strict=True)):
        assert a == b, f"tick {i}: over Zenoh {a} != in process {b}"
    changes = [p.phase.value for k, p in enumerate(phases.msgs)
               if k == 0 or p.phase != phases.msgs[k - 1].phase]
    assert changes == expected_phases
