"""One engine per robot (issue 21): an engine claims the robot by a liveliness token; a second
one is refused (or waits as standby and takes over); engine and robot both report competing
engines, and the robot tells head commands of two publishers apart by the GIDs of their
attachments."""

from __future__ import annotations

import threading

import pytest
from drivers_fakes import FakeClock, FakeEngine, Recorder, wait_until
from test_drivers_faults import (
    FAST,
    connected,
    engine_side,
    events_of,
    frame,
    robot_side,
    sees_claim,
)

from gazebot.core.runtime import GazeLoop
from gazebot.io.drivers.engine_node import EngineNode, EngineNodeConfig, EngineRefused
from gazebot.io.drivers.ownership import Claim, Ownership
from gazebot.io.drivers.rmw.node import RosNode
from gazebot.io.drivers.zenoh_driver import ZenohRobotDriver
from gazebot.io.ros2 import convert, topics
from gazebot.io.ros2.values import JointGoal

pytestmark = pytest.mark.zenoh


def second_engine(bus, config=FAST, name="engine2"):
    drv = ZenohRobotDriver(bus.connector(), bus.names, name)
    bus.closers.append(drv.close)
    return EngineNode(GazeLoop(FakeEngine()), drv, config), drv


def health_of(node) -> Recorder:
    return Recorder(node, topics.DIAGNOSTICS, convert.health_of)


def test_claims_order_by_start_then_session_and_parse_back():
    a = Claim(5, "ab12", "engine", "/gazebot", 3)
    assert Claim.parse(a.key()) == a
    assert a.key() == "@gazebot_owner/3/%gazebot/5/ab12/engine"
    assert sorted([Claim(6, "00", "e"), a, Claim(5, "ab11", "z")])[0] == Claim(5, "ab11", "z")
    for bad in ("@gazebot_owner/3/%gazebot/5/ab12", "@gazebot_owner/x/%g/5/ab/e",
                "@gazebot_owner/3/%g/5/XY/e", "@gazebot_owner/3/%g/5/ab/bad-name",
                "other/1/2/3/4/5"):
        with pytest.raises(ValueError):
            Claim.parse(bad)


def test_a_second_engine_is_refused_and_both_engines_and_the_robot_report_it(bus):
    ep = robot_side(bus)
    node1, drv1, _, th1 = engine_side(bus)
    events = events_of(ep)
    status = health_of(ep)
    assert wait_until(lambda: connected(ep, drv1))
    th1.start()
    assert node1.ready.wait(30)
    node2, drv2 = second_engine(bus)
    assert sees_claim(drv2, drv1)
    with pytest.raises(EngineRefused, match=r"another engine, engine \(session \w+\), already "
                       r"commands the robot under " + bus.names.namespace):
        node2.start()
    assert node2.role == "refused" and not drv2.owns_robot() and drv1.owns_robot()
    # the refused engine, the owner and the robot each report it
    assert wait_until(lambda: events.where(kind="competing_engine", source="engine2"))
    assert events.where(kind="competing_engine", source="engine2")[0].info["role"] == "refused"
    assert wait_until(lambda: events.where(kind="competing_engine", source="engine"))
    owner_report = events.where(kind="competing_engine", source="engine")[0]
    assert owner_report.info["role"] == "owner" and "engine2" in owner_report.info["new"][0]
    assert wait_until(lambda: events.where(kind="competing_engine", source="sim"))
    robot_report = events.where(kind="competing_engine", source="sim")[0]
    assert robot_report.info["owner"].startswith("engine ")
    assert len(robot_report.info["engines"]) == 2
    # the owner's diagnostics name the rival while it is there
    assert wait_until(lambda: any(s.node == "engine" and s.state == "degraded"
                                  and s.values.get("rivals") for s in status.msgs))
    drv2.close()
    assert wait_until(lambda: drv1.rival_engines() == [])
    ep.publish_tracking(frame(0.0))
    assert wait_until(lambda: ep.head.peek() is not None)  # the owner goes on
    assert th1.is_alive() and node1.role == "owner"


def test_a_standby_engine_commands_nothing_until_the_owner_stops_then_takes_over(bus):
    ep = robot_side(bus)
    node1, drv1, stop1, th1 = engine_side(bus)
    events = events_of(ep)
    assert wait_until(lambda: connected(ep, drv1))
    th1.start()
    assert node1.ready.wait(30)
    node2, drv2 = second_engine(bus, EngineNodeConfig(silence_after=1e3, heartbeat_period=0.05,
                                                      resync=False, standby=True))
    stop2 = threading.Event()
    th2 = threading.Thread(target=node2.run, kwargs={"stop": stop2}, daemon=True)
    bus.closers.append(lambda: (stop2.set(), th2.is_alive() and th2.join(timeout=5)))
    assert sees_claim(drv2, drv1)
    th2.start()
    assert node2.ready.wait(30) and node2.role == "standby"
    ep.publish_tracking(frame(0.0))
    assert wait_until(lambda: node1.commands_sent >= 1)
    assert node2.commands_sent == 0 and node2.frames_processed == 0
    # the owner stops: its claim vanishes with it, the standby engine takes over
    stop1.set()
    th1.join(timeout=5)
    drv1.close()
    assert wait_until(lambda: events.where(kind="engine_took_over", source="engine2"))
    assert wait_until(lambda: node2.role == "owner")
    # the robot obeys engine2 once it has seen engine's claim go (not necessarily yet)
    assert wait_until(lambda: ep.owners.owner() is not None
                      and ep.owners.owner().zid == drv2.ros.zid)
    n = ep.head.count
    ep.publish_tracking(frame(0.1))
    assert wait_until(lambda: node2.commands_sent >= 1 and ep.head.count > n)
    assert th2.is_alive()


def head_command(t: float, pan: float):
    return convert.joint_trajectory(JointGoal(t, {"head_pan": pan}, {}, 0.1))


def test_the_robot_reports_head_commands_from_two_publishers_by_their_gids(bus):
    # Two publishers compete while both commanded within compete_window (1 s) on the robot's
    # clock: one the test moves, so no stall between the two commands lets the window expire.
    clock = FakeClock(100.0)
    ep = robot_side(bus, clock=clock)
    events = events_of(ep)
    status = health_of(ep)
    a = RosNode(bus.connector(), bus.names, "ros_engine_a")
    b = RosNode(bus.connector(), bus.names, "ros_engine_b")
    bus.closers += [a.close, b.close]
    pa = a.publisher(topics.HEAD_COMMAND.name, topics.HEAD_COMMAND.type)
    pb = b.publisher(topics.HEAD_COMMAND.name, topics.HEAD_COMMAND.type)
    a.announce()
    b.announce()
    # a claims the robot as an engine does (issue 30: the robot obeys only its owner)
    claim = Ownership(a.session, bus.names, a.name, graph=a.graph)
    bus.closers.append(claim.undeclare)
    claim.declare()
    assert wait_until(lambda: ep.owners.owner() is not None)
    assert wait_until(lambda: pa.subscribed() and pb.subscribed())
    assert wait_until(lambda: len(ep.ros.graph.endpoints(ep._head_topic, "MP")) == 2)
    pa.publish(head_command(0.0, 0.1))
    assert wait_until(lambda: ep.head.count == 1)
    assert not events.where(kind="competing_engine")  # one publisher is no competition
    pb.publish(head_command(0.0, -0.1))  # not the owner: dropped, and the pair reported
    assert wait_until(lambda: events.where(kind="competing_engine"))
    assert wait_until(lambda: ep.unidentified() == {ep._head_topic: 1})
    assert ep.head.count == 1
    [report] = events.where(kind="competing_engine")
    assert sorted(report.info["gids"]) == sorted([pa.gid.hex(), pb.gid.hex()])
    assert {p.split(" ")[0] for p in report.info["publishers"]} == {"ros_engine_a",
                                                                   "ros_engine_b"}
    ep.heartbeat()
    assert wait_until(lambda: any(s.node == "sim" and s.values.get("head_publishers") == 2
                                  and s.state == "degraded" for s in status.msgs))
    # more than the window on, only the owner commands: one publisher, no competition
    clock.now += 1.5
    pa.publish(head_command(0.1, 0.2))
    assert wait_until(lambda: ep.head.count == 2)
    assert ep.head_publishers() == 1
    assert len(events.where(kind="competing_engine")) == 1


def test_the_robot_drops_head_commands_of_an_engine_that_does_not_own_it(bus):
    ep = robot_side(bus)
    drv1 = ZenohRobotDriver(bus.connector(), bus.names, "engine")
    drv2 = ZenohRobotDriver(bus.connector(), bus.names, "engine2")
    bus.closers += [drv1.close, drv2.close]
    drv1.claim()
    drv2.claim()
    # claim() waits a bounded time for the claims alive; on a busy machine the second engine
    # may learn of the first's claim only afterwards, from the liveliness watch: both then agree.
    assert wait_until(lambda: drv1.owns_robot() and not drv2.owns_robot())
    assert wait_until(lambda: len(ep.owners.claims()) == 2)
    assert wait_until(lambda: len(ep.ros.graph.endpoints(ep._head_topic, "MP")) == 2)
    drv2.send_head(JointGoal(0.0, {"head_pan": 0.5}))
    head = ep.names.resolve(topics.HEAD_COMMAND.name)
    assert wait_until(lambda: ep.dropped().get(head) == 1)
    assert "does not own the robot" in ep.drops.reasons()[head]
    drv1.send_head(JointGoal(0.0, {"head_pan": 0.2}))
    assert wait_until(lambda: ep.head.peek() is not None)
    assert ep.head.peek().positions == {"head_pan": 0.2} and ep.head.count == 1
