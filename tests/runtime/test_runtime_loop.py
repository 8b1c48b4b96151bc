"""The one runtime loop: the same commands in process and over Zenoh, the behavior's own
tracking-loss timings, and the safety checks."""

from __future__ import annotations

import math
import threading
import time

import numpy as np
import pytest

from gazebot.runtime import GazeLoop
from gazebot.types import GazeCommand, Phase, TrackingFrame


@pytest.fixture(scope="module")
def recorded_handover():
    """One simulated Sawyer handover as a robot would report it, tick by tick: the tracking
    sample, the robot controller's events and the measured joints (120 Hz)."""
    from gazebot.sim import HandoverSimulation

    ticks = []
    with HandoverSimulation("sawyer", "default", seed=2) as sim:
        done_at = None
        while sim.t < 12.0:
            sim.step(1 / 120)
            ticks.append((sim.tracking(), sim.robot_events(), dict(sim.joint_state())))
            if done_at is None and sim.done:
                done_at = sim.t
            if done_at is not None and sim.t > done_at + 0.5:
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
        c = loop.tick(frame.t, frame, joints=joints)
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


def test_silence_holds_for_the_behaviors_hold_time_then_looks_at_its_target():
    loop = GazeLoop.from_config("sawyer", "face-hand-face")
    spec = loop.engine.behavior_spec.tracking_lost
    gap = loop.engine.detector.config.max_gap_hold
    face = np.array([1.1, -0.3, 1.6])
    hand = np.array([1.0, 0.3, 0.9])
    t = 0.0
    for _ in range(120):  # 1 s of tracking: the gaze settles on the face
        cmd = loop.tick(t, TrackingFrame.make(t, giver_hand=hand, receiver_hand=[0.4, 0, 0.9],
                                              giver_face=face))
        t += 1 / 120
    last = t - 1 / 120
    assert cmd.tracking == "ok" and cmd.target == "face"
    states = []
    while t < last + gap + spec.hold_s + 1.0:  # silence at 30 Hz
        cmd = loop.tick(t)
        states.append((t, cmd.tracking, cmd.target))
        assert not cmd.answers_sample
        t += 1 / 30
    # bridged by the detector for max_gap_hold, then held for the behavior's hold_s, then lost
    first_hold = next(t for t, s, _ in states if s == "hold")
    first_lost = next(t for t, s, _ in states if s == "lost")
    assert last + gap < first_hold <= last + gap + 1 / 30 + 1e-9
    # the behavior's hold counts from the last valid sample (the tracking_lost event's time)
    lost_at = max(last + spec.hold_s, first_hold)
    assert lost_at - 1e-9 <= first_lost <= lost_at + 1 / 30 + 1e-9
    assert all(s == "ok" for t, s, _ in states if t <= last + gap)
    lost = [c for c in states if c[1] == "lost"]
    assert lost and all(target == spec.target for _, _, target in lost)
    np.testing.assert_allclose(cmd.target_point, face)
    # samples return: ok again
    cmd = loop.tick(t, TrackingFrame.make(t, giver_hand=hand, receiver_hand=[0.4, 0, 0.9],
                                          giver_face=face))
    assert cmd.tracking == "ok" and cmd.answers_sample


class _Engine:
    """Returns whatever command it is given, on a real robot model."""

    def __init__(self, robot) -> None:
        self.robot = robot
        self.next: GazeCommand | None = None
        self.phase = Phase.IDLE

    def step(self, frame, arm=None) -> GazeCommand:
        return self.next

    def tracking_state(self, t: float) -> str:
        return "ok"


@pytest.fixture(scope="module")
def sawyer():
    from gazebot.kinematics import RobotModel

    return RobotModel.load("sawyer")


def _cmd(head, yaw=0.0, pitch=0.0, t=1.0, point=(1.0, 0.0, 1.5)):
    return GazeCommand(t=t, phase=Phase.IDLE, target="face", target_point=np.array(point),
                       head=head, eye_yaw=yaw, eye_pitch=pitch)


@pytest.mark.parametrize("bad", [
    {"head_pan": math.nan}, {"head_pan": math.inf},
])
def test_a_non_finite_head_goal_is_never_returned(sawyer, bad):
    engine = _Engine(sawyer)
    loop = GazeLoop(engine)
    engine.next = _cmd(bad)
    assert loop.tick(1.0, TrackingFrame(t=1.0)) is None
    engine.next = _cmd({"head_pan": 0.1}, yaw=math.nan)
    assert loop.tick(1.1, TrackingFrame(t=1.1)) is None
    assert loop.unsafe == 2


def test_out_of_limit_head_and_eye_commands_are_clipped_into_the_limits(sawyer):
    engine = _Engine(sawyer)
    loop = GazeLoop(engine)
    engine.next = _cmd({"head_pan": 50.0}, yaw=3.0, pitch=-3.0)
    cmd = loop.tick(1.0, TrackingFrame(t=1.0))
    assert cmd.head["head_pan"] == pytest.approx(float(sawyer.upper[0]))
    assert cmd.eye_yaw == pytest.approx(sawyer.eyes.yaw_range[1])
    assert cmd.eye_pitch == pytest.approx(sawyer.eyes.pitch_range[0])
    assert loop.clipped == 1 and 0.0 <= cmd.blink <= 1.0


def test_distance_is_from_the_gaze_frame_at_the_commanded_head_pose(sawyer):
    engine = _Engine(sawyer)
    loop = GazeLoop(engine)
    point = np.array([1.2, 0.4, 1.3])
    engine.next = _cmd({"head_pan": 0.3}, point=point)
    cmd = loop.tick(1.0, TrackingFrame(t=1.0))
    origin = sawyer.gaze_pose(sawyer.head_vector({"head_pan": 0.3})).position
    assert cmd.distance == pytest.approx(float(np.linalg.norm(point - origin)))
    engine.next = _cmd({"head_pan": 0.3}, point=(math.nan,) * 3, t=1.1)
    assert loop.tick(1.1, TrackingFrame(t=1.1)).distance is None


def test_big_gaze_shifts_bring_blinks_and_the_blink_stream_is_seeded(sawyer):
    def blinks(seed):
        loop = GazeLoop(_Engine(sawyer), seed=seed)
        out = []
        for i in range(600):  # the target jumps 60 degrees every second
            y = 1.0 if (i // 120) % 2 else -1.0
            loop.engine.next = _cmd({"head_pan": 0.0}, t=i / 120, point=(1.0, y, 1.5))
            out.append(loop.tick(i / 120, TrackingFrame(t=i / 120)).blink)
        return out, loop.blinks.blink_times

    a, times = blinks(0)
    b, _ = blinks(0)
    assert a == b and max(a) == 1.0
    hit = sum(any(abs(bt - k) < 0.05 for bt in times) for k in range(1, 5))
    assert hit >= 2  # shift_probability 0.9: most jumps blink at once
