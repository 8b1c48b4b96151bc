"""Transport and faults with real Zenoh sessions on loopback and a fake engine, on the rmw_zenoh
wire (ROS 2 messages in CDR under ``<domain>/<topic>/<type>/<hash>``).

Each test has its own namespace and port; the robot side listens, the engine connects.
"""

from __future__ import annotations

import dataclasses
import threading

import numpy as np
import pytest
from drivers_fakes import FakeClock, FakeEngine, Recorder, wait_until

from gazebot.core.runtime import GazeLoop
from gazebot.core.types import Event, EventKind, TrackingFrame
from gazebot.io.drivers.engine_node import EngineNode, EngineNodeConfig, current_handover
from gazebot.io.drivers.ownership import OwnershipWatch
from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
from gazebot.io.drivers.zenoh_robot import ZenohRobotEndpoint
from gazebot.io.ros2 import convert, topics
from gazebot.io.ros2.codec import Codec
from gazebot.io.ros2.typestore import typestore

pytestmark = pytest.mark.zenoh

# Fast heartbeats; no silence ticks (a loaded machine may pause between samples) except where a
# test is about silence; no resync at start except where a test is about it (then it waits long
# enough for a slow machine: it returns as soon as the joint state and the history arrived).
FAST = EngineNodeConfig(silence_after=1e3, heartbeat_period=0.05, resync=False)
SILENCE = EngineNodeConfig(silence_after=0.05, heartbeat_period=0.05, resync=False)
RESYNC = EngineNodeConfig(silence_after=1e3, heartbeat_period=0.05, resync_timeout=10.0)


def events_of(node, topic=topics.EVENTS) -> Recorder:
    return Recorder(node, topic, convert.event_of)


def health_of(node) -> Recorder:
    """The nodes' statuses on /diagnostics (``node``, ``state``, ``values``)."""
    return Recorder(node, topics.DIAGNOSTICS, convert.health_of)


def heads_of(node) -> Recorder:
    """The head goals (joint -> rad) sent on head/command."""
    return Recorder(node, topics.HEAD_COMMAND, lambda m: convert.trajectory_goal(m).positions)


def targets_of(node) -> Recorder:
    """``(t, point)`` of the gaze targets sent."""
    return Recorder(node, topics.GAZE_TARGET, convert.point_of)


def robot_side(bus, peer_timeout=2.0, clock=None) -> ZenohRobotEndpoint:
    kw = {"clock": clock} if clock is not None else {}
    ep = ZenohRobotEndpoint(bus.listener(), bus.names, "sim", peer_timeout=peer_timeout, **kw)
    bus.closers.append(ep.close)
    return ep


def engine_side(bus, engine=None, config=FAST, peer_timeout=2.0, clock=None):
    kw = {"clock": clock} if clock is not None else {}
    drv = ZenohRobotDriver(bus.connector(), bus.names, "engine", peer_timeout=peer_timeout,
                           **kw)
    # The robot obeys only the engine that owns it (issue 30): claim as ``start()`` does, so
    # tests that tick the node directly are obeyed too (``start()`` claims only once).
    drv.claim()
    node = EngineNode(GazeLoop(engine or FakeEngine()), drv, config)
    stop = threading.Event()
    th = threading.Thread(target=node.run, kwargs={"stop": stop}, daemon=True)

    def close():  # stop the loop before closing its driver
        stop.set()
        if th.is_alive():
            th.join(timeout=5)
        drv.close()

    bus.closers.append(close)
    return node, drv, stop, th


def connected(ep, drv) -> bool:
    return ep.peers().get("engine") and drv.peers().get("sim")


def sees_claim(drv, owner) -> bool:
    """Wait until ``drv``'s session, before it claims the robot, sees ``owner``'s claim as the
    one the claims settle on (its engine node in ``drv``'s graph): a new session may learn of
    the first engine only after ``claim()`` stopped waiting for the claims alive."""
    watch = OwnershipWatch(drv.session, drv.names, graph=drv.ros.graph)
    try:
        return wait_until(lambda: watch.owner() == owner._ownership.claim)
    finally:
        watch.undeclare()


def frame(t, hand_x=1.0, face=(1.0, 0.3, 1.5)):
    return TrackingFrame.make(t, giver_hand=[hand_x, 0.0, 1.0], giver_face=face)


def test_tracking_in_head_command_out_over_the_bus(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus)
    events = events_of(ep)
    targets = targets_of(ep)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    for i in range(20):
        ep.publish_tracking(frame(i / 120, hand_x=1.0 - i * 0.02))
    # the last sample's gaze target, stamped with its robot time
    assert wait_until(lambda: targets.msgs and targets.msgs[-1][0] == pytest.approx(19 / 120))
    assert wait_until(lambda: ep.head.peek() is not None)
    cmd = ep.head.peek()
    assert cmd.positions["head_pan"] == pytest.approx(np.arctan2(0.3, 1.0))
    assert cmd.time_from_start > 0 and set(cmd.velocities) == {"head_pan"}
    assert wait_until(lambda: ep.eyes.peek() is not None)
    # the fake engine's phase event is published once, with the engine as source
    assert wait_until(lambda: events.where(kind="reach_started"))
    [reach] = events.where(kind="reach_started")
    assert reach.source == "engine" and reach.category == "phase"


def test_robot_events_reach_the_engine(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    reach = Event(EventKind.ROBOT_REACH_STARTED, 0.5, 0.5, {"planned_duration": 1.2})
    ep.publish_robot_event(reach)
    ep.publish_tracking(frame(0.6))
    assert wait_until(lambda: node.engine.notified)
    assert node.engine.notified == [reach]


def _key(node, topic, type_name=None):
    codec = Codec.for_type(typestore(), type_name or topic.type)
    return node.names.key(node.names.resolve(topic.name), codec.info.dds_name, codec.info.hash)


def test_bad_input_is_counted_dropped_reported_with_its_topic_and_never_crashes(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus)
    status = health_of(ep)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    hand = ep.names.resolve(topics.GIVER_HAND.name)
    nan = Codec.for_type(typestore(), convert.POINT_STAMPED).encode(
        convert.point_stamped(0.5, [1.0, 0.0, 1.0], "world"))
    nan = nan[:-24] + np.array([np.nan, 0.0, np.inf]).tobytes()  # x NaN, z inf on the wire
    cdr_garbage = [b"", b"\x00\xff", b"\x00\x01\x00\x00\x01", b"garbage bytes!",
                   nan[:20],  # truncated
                   nan,  # NaN / inf coordinates
                   b"\x00\x01\x00\x00" + b"\x00" * (5 * 1024 * 1024)]  # oversized
    import zenoh

    block = zenoh.CongestionControl.BLOCK  # 5 MB puts must not crowd the others out in Zenoh
    for raw in cdr_garbage:
        for topic in (topics.GIVER_HAND, topics.JOINT_STATES, topics.EVENTS, topics.DIAGNOSTICS):
            ep.session.put(_key(ep, topic), raw, congestion_control=block)
        # the robot side drops these
        ep.session.put(_key(ep, topics.HEAD_COMMAND), raw, congestion_control=block)
    ep.publish_tracking(frame(1.0))
    assert wait_until(lambda: ep.head.peek() is not None)
    n = len(cdr_garbage)
    resolved = {t: ep.names.resolve(t.name) for t in
                (topics.GIVER_HAND, topics.JOINT_STATES, topics.EVENTS, topics.DIAGNOSTICS)}
    assert wait_until(lambda: drv.dropped().get(hand) == n), (drv.dropped(), drv.drops.reasons())
    assert wait_until(lambda: drv.dropped() == {r: n for r in resolved.values()}), (
        drv.dropped(), drv.drops.reasons())
    assert wait_until(lambda: ep.dropped().get(ep.names.resolve(topics.HEAD_COMMAND.name)) == n)
    reasons = drv.drops.reasons()
    assert "oversized" in reasons[hand]
    # the engine's heartbeat reports the counts by topic and the loop is still alive
    assert wait_until(lambda: any(s.node == "engine" and s.values.get(f"dropped/{hand}") == n
                                  for s in status.msgs))
    assert th.is_alive() and node.frames_processed == 1


def test_nan_coordinates_and_foreign_frames_are_dropped_and_counted_with_their_topic(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    face = ep.names.resolve(topics.GIVER_FACE.name)
    msg = convert.point_stamped(0.5, [1.0, 0.0, 1.0], "world")
    msg.point.x = float("nan")
    codec = Codec.for_type(typestore(), convert.POINT_STAMPED)
    ep.session.put(_key(ep, topics.GIVER_FACE), codec.encode(msg))
    assert wait_until(lambda: drv.dropped().get(face) == 1)
    assert "not finite" in drv.drops.reasons()[face]
    # a point in another frame than the robot base frame is not used either
    ep.session.put(_key(ep, topics.GIVER_FACE), codec.encode(
        convert.point_stamped(0.6, [1.0, 0.0, 1.0], "camera")))
    assert wait_until(lambda: drv.dropped().get(face) == 2)
    assert "frame_id 'camera'" in drv.drops.reasons()[face]
    assert th.is_alive() and node.frames_processed == 0


def test_a_wrong_type_hash_is_reported_as_a_type_mismatch_with_topic_and_types(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus)
    warnings = []
    node.warn = warnings.append
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    hand = ep.names.resolve(topics.GIVER_HAND.name)
    good = _key(ep, topics.GIVER_HAND)
    other = good.rsplit("/", 1)[0] + "/RIHS01_" + "ab" * 32  # another version of the type
    raw = Codec.for_type(typestore(), convert.POINT_STAMPED).encode(
        convert.point_stamped(0.5, [1.0, 0.0, 1.0], "world"))
    ep.session.put(other, raw)
    ep.session.put(_key(ep, topics.GIVER_HAND, convert.JOINT_STATE), raw)  # another type
    assert wait_until(lambda: drv.dropped().get(hand) == 2)
    mismatch = drv.type_mismatches()[hand]
    assert mismatch.topic == hand and mismatch.expected[0].startswith(convert.POINT_STAMPED)
    assert wait_until(lambda: any("type mismatch on " + hand in w for w in warnings))
    assert node.frames_processed == 0 and th.is_alive()


def test_tracking_stop_ticks_the_loop_whose_policy_holds_then_looks_at_the_last_face(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus, config=SILENCE)
    events = events_of(ep)
    heads = heads_of(ep)
    targets = targets_of(ep)
    status = health_of(ep)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    last_face = (1.2, -0.4, 1.6)
    ep.publish_tracking(frame(0.0))
    ep.publish_tracking(frame(1 / 120, face=last_face))
    assert wait_until(lambda: node.frames_processed == 2)
    # silence: the node ticks the loop without samples; the engine's policy holds, then loses
    assert wait_until(lambda: events.where(kind="tracking_stale"))
    assert wait_until(lambda: events.where(kind="tracking_timeout"))
    [timeout] = events.where(kind="tracking_timeout")
    assert timeout.info["face"] == pytest.approx(list(last_face))
    # meanwhile the head looks at the last face, commanded by silence ticks
    assert wait_until(lambda: len(heads.msgs) > 2)
    assert heads.msgs[-1]["head_pan"] == pytest.approx(np.arctan2(-0.4, 1.2))
    assert wait_until(lambda: any(s.node == "engine" and s.values.get("tracking") == "lost"
                                  and s.state == "degraded" for s in status.msgs))
    # tracking returns: resumed, the sample answered. From the events, not the live state: a
    # silence tick 0.05 s after the sample (silence_after) may already hold and lose again.
    ep.publish_tracking(frame(30.0))
    assert wait_until(lambda: events.where(kind="tracking_resumed"))
    [resumed] = events.where(kind="tracking_resumed")
    assert resumed.t == 30.0  # the sample's own tick, whose tracking was ok
    assert wait_until(lambda: any(t == 30.0 for t, _ in targets.msgs))


def test_restarted_engine_resyncs_from_event_history_and_joint_state(bus):
    ep = robot_side(bus)
    node1, drv1, stop1, th1 = engine_side(bus)
    assert wait_until(lambda: connected(ep, drv1))
    th1.start()
    ep.publish_robot_event(Event(EventKind.ROBOT_REACH_STARTED, 0.1, 0.1, {"planned_duration": 1}))
    for i in range(10):
        ep.publish_tracking(frame(0.2 + i / 120, hand_x=0.9 - 0.05 * i))
    assert wait_until(lambda: any(m.kind == "reach_started" for m in ep.history()))
    stop1.set()
    th1.join(timeout=5)
    drv1.close()
    assert wait_until(lambda: not ep.peers().get("engine"))
    # the robot keeps publishing its joint state; a fresh engine joins mid-handover
    ep.publish_joint_state(1.0, {"head_pan": 0.4, "right_j0": 0.1})
    engine2 = FakeEngine()
    node2, drv2, _, th2 = engine_side(bus, engine=engine2, config=RESYNC)
    assert wait_until(lambda: connected(ep, drv2))
    ep.publish_joint_state(1.0, {"head_pan": 0.4, "right_j0": 0.1})
    replayed = node2.start()
    assert [e.kind for e in engine2.resynced] == [
        EventKind.ROBOT_REACH_STARTED, EventKind.REACH_STARTED]
    assert replayed == 2 and engine2.phase.value == "reach"
    assert engine2.reset_heads == [{"head_pan": 0.4}]
    # the replayed robot event is not notified a second time
    node2.tick()
    assert engine2.notified == []


def test_history_replays_only_the_current_handover():
    ev = [Event(k, t, t) for k, t in [
        (EventKind.REACH_STARTED, 1), (EventKind.HANDOVER_DONE, 5), (EventKind.REACH_STARTED, 8),
        (EventKind.ROBOT_REACH_STARTED, 7.5)]]
    assert [e.t for e in current_handover(ev)] == [7.5, 8]
    assert [e.kind for e in current_handover(ev[:2])] == [EventKind.HANDOVER_DONE]
    assert current_handover([]) == []


def test_robot_gone_engine_keeps_running_and_reports_peer_lost(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus)
    events = events_of(drv)
    status = health_of(drv)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    ep.publish_tracking(frame(0.0))
    assert wait_until(lambda: node.frames_processed == 1)
    ep.close()
    ep.session.close()  # the simulator process is gone
    assert wait_until(lambda: events.where(kind="peer_lost"))
    assert events.where(kind="peer_lost")[0].info == {"peer": "sim"}
    assert wait_until(lambda: any(s.node == "engine" and s.values.get("peer/sim") == "lost"
                                  and s.state == "degraded" for s in status.msgs))
    n = len(status.msgs)
    assert wait_until(lambda: len(status.msgs) > n + 2)  # still beating
    assert th.is_alive()


def test_robot_whose_heartbeat_stops_counts_as_lost(bus):
    clock = FakeClock(100.0)  # the engine's view of heartbeat ages: moved by hand
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus, peer_timeout=0.2, clock=clock)
    events = events_of(drv)
    status = health_of(drv)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    ep.heartbeat()
    assert wait_until(lambda: any(s.node == "sim" for s in status.msgs))
    assert drv.peers() == {"sim": True}
    # the simulator hangs: its session (and token) stays, its heartbeats stop. The clock moves
    # on while we wait: on a busy machine the driver may take the last heartbeat in only after a
    # single jump, stamping it fresh; time passing on must still make it stale.
    def hung() -> bool:
        clock.now += 0.5
        return bool(events.where(kind="peer_lost"))

    assert wait_until(hung)
    # it beats again (as a live robot does): restored. Time keeps passing on the driver's clock
    # (a frozen clock would leave the driver's tracking wait, which ends by that clock, waiting
    # for ever), by less than the 0.2 s peer timeout between two beats.
    def beating() -> bool:
        clock.now += 0.02
        ep.heartbeat()
        return bool(events.where(kind="peer_restored"))

    assert wait_until(beating, poll=0.1)


class CountingRenderer:
    def __init__(self):
        self.calls = 0

    def render(self, yaw, pitch, blink=0.0, distance=None):
        self.calls += 1
        return np.full((24, 40, 3), 200, np.uint8)


def test_eye_frames_are_rendered_only_while_someone_subscribes(bus):
    ep = robot_side(bus)  # draws its own eyes: does not ask for frames
    drv = ZenohRobotDriver(bus.connector(), bus.names, "engine")
    bus.closers.append(drv.close)
    drv.claim()  # displays, too, draw only the owner's eyes
    renderer = CountingRenderer()
    node = EngineNode(GazeLoop(FakeEngine()), drv, FAST, eye_renderer=renderer)
    assert wait_until(lambda: connected(ep, drv))
    for i in range(5):
        node.on_tracking(ep.publish_tracking(frame(i / 120)))
    assert renderer.calls == 0 and node.commands_sent == 5
    # a display that wants frames joins
    viewer = ZenohRobotEndpoint(bus.connector(), bus.names, "display", eye_frames=True)
    bus.closers.append(viewer.close)
    assert wait_until(drv.wants_eye_frames)
    # The one frame below is obeyed only once the display knows the owner and its publisher
    # (a new session may see them after the engine saw its subscription: unidentified, dropped).
    frames = viewer.names.resolve(topics.EYE_IMAGE.name)
    assert wait_until(lambda: viewer.owners.owner() == drv._ownership.claim
                      and viewer.ros.graph.endpoints(frames, "MP"))
    node.on_tracking(ep.publish_tracking(frame(1.0)))
    assert renderer.calls == 1
    assert wait_until(lambda: viewer.eye_frame.peek() is not None)
    assert convert.image_of(viewer.eye_frame.peek()).shape == (24, 40, 3)


def test_listening_on_a_taken_endpoint_is_a_clear_error(bus):
    from gazebot.io.drivers.session import BusConfig, open_session

    bus.listener()
    with pytest.raises(ValueError, match="could not open a Zenoh session.*" + bus.endpoint):
        open_session(BusConfig(bus.names, listen=(bus.endpoint,)))


def test_robot_clock_going_back_resets_and_resyncs_the_engine(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus, config=RESYNC)
    events = events_of(ep)
    assert wait_until(lambda: connected(ep, drv))
    ep.publish_joint_state(0.0, {"head_pan": 0.2})
    assert wait_until(lambda: drv.joint_state() is not None)
    th.start()
    assert node.ready.wait(30)
    ep.publish_tracking(frame(5.0, hand_x=0.5))
    assert wait_until(lambda: node.engine.phase.value == "reach")
    ep.publish_joint_state(0.0, {"head_pan": -0.3})
    # keys keep their own order only: the new joint state first, then the sample
    assert wait_until(lambda: drv.joint_state().position["head_pan"] == -0.3)
    for i in range(3):  # the simulator restarted (a restart is taken from 3 samples in a row)
        ep.publish_tracking(frame(i / 120))
    assert wait_until(lambda: events.where(kind="tracking_clock_reset"))
    assert wait_until(lambda: node.engine.frames
                      and node.engine.frames[-1].t == pytest.approx(2 / 120))
    assert node.tracking_backwards == 2
    assert node.engine.reset_heads == [{"head_pan": 0.2}, {"head_pan": -0.3}]


def test_pose_stamped_and_tf_frames_are_tracking_too_and_remapped_topics_are_used(bus):
    from gazebot.io.drivers.rmw.names import Names
    from gazebot.io.drivers.rmw.node import RosNode

    names = Names(bus.names.namespace, {"gaze_target": "/robot/look_at"},
                  tf_frames={"giver_face": "mocap/face"})
    ep = ZenohRobotEndpoint(bus.listener(), names, "sim")
    bus.closers.append(ep.close)
    drv = ZenohRobotDriver(bus.connector(), names, "engine")
    bus.closers.append(drv.close)
    mocap = RosNode(ep.session, names, "mocap")
    bus.closers.append(mocap.close)
    pose = mocap.publisher(topics.GIVER_HAND.name, convert.POSE_STAMPED)
    tf = mocap.publisher(topics.TF.name, topics.TF.type)
    targets = Recorder(ep, topics.GAZE_TARGET, convert.point_of)  # resolves the remap
    assert targets.key.startswith("0/robot/look_at/")
    node = EngineNode(GazeLoop(FakeEngine()), drv, FAST)
    assert wait_until(lambda: connected(ep, drv))
    # The engine waits for a sample's parts whose topics it knows a publisher of: until its
    # graph lists the mocap's two publishers, a face could complete a sample without its hand.
    hand_topic, tf_topic = names.resolve(topics.GIVER_HAND.name), names.resolve(topics.TF.name)
    assert wait_until(lambda: drv.ros.graph.endpoints(hand_topic, "MP")
                      and drv.ros.graph.endpoints(tf_topic, "MP"))
    for i in range(3):
        t = 0.5 + i / 120
        sample = TrackingFrame.make(t, giver_hand=[0.9, 0.0, 1.0], giver_face=[1.1, 0.2, 1.6])
        pose.publish(convert.pose_stamped(t, sample.giver_hand, "world"))
        tf.publish(convert.tracking_tf(TrackingFrame.make(t, giver_face=sample.giver_face),
                                       "world", {"giver_face": "mocap/face"}))
    got = []

    def three_samples() -> bool:
        if (m := drv.wait_tracking(0.05)) is not None:
            got.append(m)
        return len(got) >= 3

    assert wait_until(three_samples)
    assert got[0].giver_hand.tolist() == [0.9, 0.0, 1.0]
    assert got[0].giver_face.tolist() == [1.1, 0.2, 1.6]
    node.on_tracking(got[-1])
    assert wait_until(lambda: targets.msgs)
    assert targets.msgs[-1][1].tolist() == [1.1, 0.2, 1.6]  # the fake engine looks at the face


class FragileEngine(FakeEngine):
    """Fails on a sample whose hand is beyond 1e100 m (what killed the engine in issue 21)."""

    def step(self, frame, arm=None):
        if frame.giver_hand is not None and abs(frame.giver_hand[0]) > 1e100:
            raise OverflowError("(34, 'Numerical result out of range')")
        return super().step(frame, arm)


def test_a_sample_that_makes_the_engine_fail_is_reported_and_the_node_goes_on(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus, engine=FragileEngine())
    events = events_of(ep)
    status = health_of(ep)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    ep.publish_tracking(frame(0.0, hand_x=1e155))
    assert wait_until(lambda: events.where(kind="node_fault"))
    [fault] = events.where(kind="node_fault")
    assert fault.category == "fault" and fault.source == "engine"
    assert fault.info["stage"] == "tracking" and "engine raised" in fault.info["error"]
    assert wait_until(lambda: any(s.node == "engine" and s.state == "degraded"
                                  and s.values.get("faults") == 1 for s in status.msgs))
    # the node goes on: the next sample is answered
    ep.publish_tracking(frame(0.1))
    assert wait_until(lambda: ep.head.peek() is not None)
    assert th.is_alive() and node.faults == 1


class FaultyEngine(FakeEngine):
    """Reports a fault it caught itself (as GazeEngine does) with a safe command."""

    def step(self, frame, arm=None):
        cmd = super().step(frame, arm)
        fault = Event(EventKind.FAULT, frame.t, frame.t,
                      {"stage": "phases", "error": "OverflowError: too big"})
        return dataclasses.replace(cmd, events=(*cmd.events, fault))


def test_a_fault_the_engine_caught_is_reported_by_the_node_and_the_command_sent(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus, engine=FaultyEngine())
    events = events_of(ep)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    ep.publish_tracking(frame(0.0))
    assert wait_until(lambda: events.where(kind="node_fault"))
    fault = events.where(kind="node_fault")[0]
    assert fault.info == {"stage": "engine phases", "error": "OverflowError: too big",
                          "faults": 1}
    assert wait_until(lambda: ep.head.peek() is not None) and th.is_alive()


def test_a_failing_subscription_callback_is_counted_and_reported_as_a_fault(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus)
    events = events_of(ep)
    drv.ros.subscription("probe", "std_msgs/msg/String", lambda msg, rx: 1 / 0)
    probe = ep.ros.publisher("probe", "std_msgs/msg/String")
    assert wait_until(lambda: connected(ep, drv) and probe.subscribed())
    th.start()
    assert node.ready.wait(30)
    probe.publish(ep.ros.store.types["std_msgs/msg/String"](data="boom"))
    assert wait_until(lambda: events.where(kind="node_fault"))
    [fault] = events.where(kind="node_fault")
    assert fault.info["stage"] == "callback " + ep.names.resolve("probe")
    assert "ZeroDivisionError" in fault.info["error"]
    assert drv.callback_faults() == {ep.names.resolve("probe"): 1} and th.is_alive()
