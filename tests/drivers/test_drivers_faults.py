"""Transport and faults with real Zenoh sessions on loopback and a fake engine.

Each test has its own robot id and port; the robot side listens, the engine connects.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest
from drivers_fakes import FakeClock, FakeEngine, wait_until

from gazebot.drivers.engine_node import EngineNode, EngineNodeConfig, current_handover
from gazebot.drivers.payloads import EventMsg, HeadCommandMsg, StatusMsg
from gazebot.drivers.zenoh_driver import ZenohRobotDriver
from gazebot.drivers.zenoh_robot import ZenohRobotEndpoint
from gazebot.runtime import GazeLoop
from gazebot.types import Event, EventKind, TrackingFrame

pytestmark = pytest.mark.zenoh

# Fast heartbeats; no silence ticks (a loaded machine may pause between samples) except where a
# test is about silence; no resync at start except where a test is about it (then it waits long
# enough for a slow machine: it returns as soon as the joint state and the history arrived).
FAST = EngineNodeConfig(silence_after=1e3, heartbeat_period=0.05, resync=False)
SILENCE = EngineNodeConfig(silence_after=0.05, heartbeat_period=0.05, resync=False)
RESYNC = EngineNodeConfig(silence_after=1e3, heartbeat_period=0.05, resync_timeout=10.0)


class Recorder:
    """Collects decoded messages of one key from a plain subscriber."""

    def __init__(self, session, key, model):
        self.msgs: list = []
        self._sub = session.declare_subscriber(
            key, lambda s: self.msgs.append(model.decode(s.payload.to_bytes())))

    def where(self, **kw):
        return [m for m in self.msgs if all(getattr(m, k) == v for k, v in kw.items())]


def robot_side(bus, peer_timeout=2.0) -> ZenohRobotEndpoint:
    ep = ZenohRobotEndpoint(bus.listener(), bus.config().keys, "sim", peer_timeout=peer_timeout)
    bus.closers.append(ep.close)
    return ep


def engine_side(bus, engine=None, config=FAST, peer_timeout=2.0, clock=None):
    kw = {"clock": clock} if clock is not None else {}
    drv = ZenohRobotDriver(bus.connector(), bus.config().keys, "engine", peer_timeout=peer_timeout,
                           **kw)
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


def frame(t, hand_x=1.0, face=(1.0, 0.3, 1.5)):
    return TrackingFrame.make(t, giver_hand=[hand_x, 0.0, 1.0], giver_face=face)


def test_tracking_in_head_command_out_over_the_bus(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus)
    events = Recorder(ep.session, ep.keys.events, EventMsg)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    sent = [ep.publish_tracking(frame(i / 120, hand_x=1.0 - i * 0.02)) for i in range(20)]
    assert wait_until(lambda: (m := ep.head.peek()) is not None and m.answers == sent[-1].seq)
    cmd = ep.head.peek()
    assert cmd.head["head_pan"] == pytest.approx(np.arctan2(0.3, 1.0))
    assert cmd.mode == "behavior" and cmd.v == 1
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


def test_malformed_payloads_are_counted_dropped_and_never_crash(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus)
    status = Recorder(ep.session, ep.keys.status, StatusMsg)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    garbage = [b"", b"\x00\xff", b"{", b"[]", b'{"v":1}', b'{"v":9,"seq":0,"t":0,"stamp":0}',
               b'{"v":1,"seq":0,"t":NaN,"stamp":0}']
    for raw in garbage:
        for key in (ep.keys.tracking, ep.keys.joint_states, ep.keys.events, ep.keys.status):
            ep.session.put(key, raw)
        ep.session.put(ep.keys.head_command, raw)  # the robot side drops these
    ep.publish_tracking(frame(1.0))
    assert wait_until(lambda: (m := ep.head.peek()) is not None and m.t == 1.0)
    n = len(garbage)
    assert wait_until(lambda: drv.dropped().get(ep.keys.tracking) == n)
    assert drv.dropped() == {k: n for k in (ep.keys.tracking, ep.keys.joint_states,
                                            ep.keys.events, ep.keys.status)}
    assert ep.dropped()[ep.keys.head_command] == n
    # the engine's heartbeat reports the counts and the loop is still alive
    assert wait_until(lambda: any(s.node == "engine" and s.dropped.get(ep.keys.tracking) == n
                                  for s in status.msgs))
    assert th.is_alive() and node.frames_processed == 1


def test_tracking_stop_ticks_the_loop_whose_policy_holds_then_looks_at_the_last_face(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus, config=SILENCE)
    events = Recorder(ep.session, ep.keys.events, EventMsg)
    heads = Recorder(ep.session, ep.keys.head_command, HeadCommandMsg)
    status = Recorder(ep.session, ep.keys.status, StatusMsg)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    last_face = (1.2, -0.4, 1.6)
    ep.publish_tracking(frame(0.0))
    ep.publish_tracking(frame(1 / 120, face=last_face))
    assert wait_until(lambda: len([m for m in heads.msgs if m.answers is not None]) == 2)
    assert all(m.mode == "behavior" for m in heads.msgs if m.answers is not None)
    # silence: the node ticks the loop without samples; the engine's policy holds, then loses
    assert wait_until(lambda: events.where(kind="tracking_stale"), timeout=10)
    assert wait_until(lambda: events.where(kind="tracking_timeout"), timeout=10)
    [timeout] = events.where(kind="tracking_timeout")
    assert timeout.info["face"] == pytest.approx(list(last_face))
    assert wait_until(lambda: heads.where(mode="tracking_lost"), timeout=10)
    fallback = heads.where(mode="tracking_lost")[-1]
    assert fallback.answers is None and fallback.target == "face"
    assert fallback.head["head_pan"] == pytest.approx(np.arctan2(-0.4, 1.2))
    assert wait_until(lambda: any(s.node == "engine" and s.tracking == "lost"
                                  and s.state == "degraded" for s in status.msgs), timeout=10)
    # tracking returns: resumed, behavior commands again
    ep.publish_tracking(frame(30.0))
    assert wait_until(lambda: events.where(kind="tracking_resumed"), timeout=10)
    assert wait_until(lambda: heads.msgs[-1].mode == "behavior" and heads.msgs[-1].t == 30.0)
    assert node.tracking == "ok"


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
    events = Recorder(drv.session, drv.keys.events, EventMsg)
    status = Recorder(drv.session, drv.keys.status, StatusMsg)
    assert wait_until(lambda: connected(ep, drv))
    th.start()
    assert node.ready.wait(30)
    ep.publish_tracking(frame(0.0))
    assert wait_until(lambda: node.frames_processed == 1)
    ep.close()
    ep.session.close()  # the simulator process is gone
    assert wait_until(lambda: events.where(kind="peer_lost"))
    assert events.where(kind="peer_lost")[0].info == {"peer": "sim"}
    assert wait_until(lambda: any(s.peers == {"sim": False} and s.state == "degraded"
                                  for s in status.msgs))
    n = len(status.msgs)
    assert wait_until(lambda: len(status.msgs) > n + 2)  # still beating
    assert th.is_alive()


def test_robot_whose_heartbeat_stops_counts_as_lost(bus):
    clock = FakeClock(100.0)  # the engine's view of heartbeat ages: moved by hand
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus, peer_timeout=0.2, clock=clock)
    events = Recorder(drv.session, drv.keys.events, EventMsg)
    status = Recorder(drv.session, drv.keys.status, StatusMsg)
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
    ep.heartbeat()
    assert wait_until(lambda: events.where(kind="peer_restored"))


class CountingRenderer:
    def __init__(self):
        self.calls = 0

    def render(self, yaw, pitch, blink=0.0, distance=None):
        self.calls += 1
        return np.full((24, 40, 3), 200, np.uint8)


def test_eye_frames_are_rendered_only_while_someone_subscribes(bus):
    ep = robot_side(bus)  # draws its own eyes: does not ask for frames
    drv = ZenohRobotDriver(bus.connector(), bus.config().keys, "engine")
    bus.closers.append(drv.close)
    renderer = CountingRenderer()
    node = EngineNode(GazeLoop(FakeEngine()), drv, FAST, eye_renderer=renderer)
    assert wait_until(lambda: connected(ep, drv))
    for i in range(5):
        node.on_tracking(ep.publish_tracking(frame(i / 120)))
    assert renderer.calls == 0 and node.commands_sent == 5
    # a display that wants frames joins
    viewer = ZenohRobotEndpoint(bus.connector(), bus.config().keys, "display", eye_frames=True)
    bus.closers.append(viewer.close)
    assert wait_until(drv.wants_eye_frames)
    node.on_tracking(ep.publish_tracking(frame(1.0)))
    assert renderer.calls == 1
    assert wait_until(lambda: viewer.eye_frame.peek() is not None)
    assert viewer.eye_frame.peek().image().shape == (24, 40, 3)


def test_listening_on_a_taken_endpoint_is_a_clear_error(bus):
    from gazebot.drivers.session import BusConfig, open_session

    bus.listener()
    with pytest.raises(ValueError, match="could not open a Zenoh session.*" + bus.endpoint):
        open_session(BusConfig(bus.robot_id, listen=(bus.endpoint,)))


def test_robot_clock_going_back_resets_and_resyncs_the_engine(bus):
    ep = robot_side(bus)
    node, drv, _, th = engine_side(bus, config=RESYNC)
    events = Recorder(ep.session, ep.keys.events, EventMsg)
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
    ep.publish_tracking(frame(0.0))  # the simulator restarted
    assert wait_until(lambda: events.where(kind="tracking_clock_reset"))
    assert wait_until(lambda: node.engine.frames and node.engine.frames[-1].t == 0.0)
    assert node.engine.reset_heads == [{"head_pan": 0.2}, {"head_pan": -0.3}]
