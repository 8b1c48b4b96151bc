"""The values nodes exchange: strict validation (types, ranges, finiteness) and lossless
conversions to and from the engine's types."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.core.types import Event, EventKind, GazeCommand, Phase, TrackingFrame
from gazebot.io.drivers.payloads import (
    ArmCommandMsg,
    EventMsg,
    EyeFrameMsg,
    HeadCommandMsg,
    PayloadError,
    StatusMsg,
    TrackingMsg,
)
from gazebot.io.drivers.session import BusConfig


def test_tracking_round_trip_keeps_points_and_missing_ones():
    frame = TrackingFrame.make(1.25, giver_hand=[0.8, 0.1, 1.0], giver_face=None, load_share=0.5)
    msg = TrackingMsg.from_frame(frame, seq=7, stamp=10.0)
    back = msg.to_frame()
    assert msg.seq == 7
    np.testing.assert_allclose(back.giver_hand, frame.giver_hand)
    assert np.all(np.isnan(back.giver_face)) and np.all(np.isnan(back.receiver_hand))
    assert back.load_share == 0.5 and back.gripper_closed is None


@pytest.mark.parametrize(
    "fields, where",
    [
        ({"t": "0"}, "t"),  # no string-to-number coercion
        ({"t": math.nan}, "t"),
        ({"giver_face": (1.0, 2.0)}, "giver_face"),
        ({"load_share": 1.5}, "load_share"),
        ({"seq": -1}, "seq"),
        ({"extra": 1}, "extra"),
    ],
)
def test_a_bad_tracking_value_is_rejected_with_the_field_named(fields, where):
    with pytest.raises(ValueError, match=where):
        TrackingMsg(**{"seq": 1, "t": 0.0, "stamp": 0.0, **fields})


def test_head_command_carries_the_goal_its_rate_of_change_and_the_time_to_reach_it():
    def cmd(t, pan):
        return GazeCommand(t=t, phase=Phase.REACH, target="hand",
                           target_point=np.array([0.7, 0.0, 1.0]), head={"head_pan": pan},
                           eye_yaw=0.05, eye_pitch=-0.02)

    first = HeadCommandMsg.from_command(cmd(2.0, 0.2), 0, 1.0)
    assert first.velocity == {"head_pan": 0.0} and first.time_from_start == pytest.approx(1 / 120)
    second = HeadCommandMsg.from_command(cmd(2.01, 0.21), 1, 1.0, previous=first)
    assert second.velocity["head_pan"] == pytest.approx(1.0)
    assert second.time_from_start == pytest.approx(0.01)
    # after a pause the goal's rate of change is unknown: arrive at rest
    later = HeadCommandMsg.from_command(cmd(5.0, 0.5), 2, 1.0, previous=second)
    assert later.velocity == {"head_pan": 0.0}
    with pytest.raises(ValueError):
        HeadCommandMsg(seq=0, t=0, stamp=0, head={"head_pan": math.nan})


def test_event_restores_engine_events_only():
    ev = Event(EventKind.ROBOT_REACH_STARTED, 1.0, 1.1, {"planned_duration": np.float64(1.5)})
    msg = EventMsg.from_event(ev, "sim", 0, 5.0)
    assert msg.category == "robot" and msg.to_event() == Event(
        EventKind.ROBOT_REACH_STARTED, 1.0, 1.1, {"planned_duration": 1.5})
    fault = EventMsg(seq=1, source="engine", category="fault", kind="tracking_timeout", t=0,
                     detected_at=0, stamp=0)
    assert fault.to_event() is None


def test_arm_command_needs_exactly_one_goal():
    assert ArmCommandMsg(seq=0, t=0, stamp=0, pose="home", gripper=0.0).pose == "home"
    with pytest.raises(ValueError, match="exactly one"):
        ArmCommandMsg(seq=0, t=0, stamp=0, pose="home", resume=True)
    with pytest.raises(ValueError):
        ArmCommandMsg(seq=0, t=0, stamp=0, pose="wave")


def test_eye_frame_encodes_and_decodes_the_image():
    img = np.zeros((30, 50, 3), np.uint8)
    img[5:10, 20:30] = (255, 0, 0)
    msg = EyeFrameMsg.from_image(img, 0, 0.0, 0.0, fmt="png")
    np.testing.assert_array_equal(msg.image(), img)
    with pytest.raises(PayloadError, match="decodable"):
        msg.model_copy(update={"data": b"not an image"}).image()


def test_status_rejects_unknown_state():
    with pytest.raises(ValueError):
        StatusMsg(node="x", seq=0, stamp=0, uptime=0, state="fine")


def test_bus_config_rejects_bad_endpoints_and_modes():
    with pytest.raises(ValueError, match="endpoint"):
        BusConfig(listen=("127.0.0.1:7447",))
    with pytest.raises(ValueError, match="router"):
        BusConfig(mode="client", connect=())
    with pytest.raises(ValueError, match="mode"):
        BusConfig(mode="broker")
    cfg = BusConfig().zenoh_config()
    assert '"tcp/127.0.0.1:7447"' in cfg.get_json("listen/endpoints")
    assert cfg.get_json("scouting/multicast/enabled") == "false"
    assert BusConfig(mode="router").zenoh_config().get_json("mode") == '"router"'
