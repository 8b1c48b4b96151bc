"""Bus payloads: versioned JSON, strict parsing, lossless round trips."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot.drivers.keys import KeyLayout
from gazebot.drivers.payloads import (
    ArmCommandMsg,
    EventHistoryMsg,
    EventMsg,
    EyeFrameMsg,
    HeadCommandMsg,
    PayloadError,
    StatusMsg,
    TrackingMsg,
)
from gazebot.drivers.session import BusConfig
from gazebot.types import Event, EventKind, GazeCommand, Phase, TrackingFrame


def test_tracking_round_trip_keeps_points_and_missing_ones():
    frame = TrackingFrame.make(1.25, giver_hand=[0.8, 0.1, 1.0], giver_face=None, load_share=0.5)
    msg = TrackingMsg.decode(TrackingMsg.from_frame(frame, seq=7, stamp=10.0).encode())
    back = msg.to_frame()
    assert msg.v == 1 and msg.seq == 7
    np.testing.assert_allclose(back.giver_hand, frame.giver_hand)
    assert np.all(np.isnan(back.giver_face)) and np.all(np.isnan(back.receiver_hand))
    assert back.load_share == 0.5 and back.gripper_closed is None


@pytest.mark.parametrize(
    "raw, where",
    [
        (b"", "<root>"),
        (b"\xff\xfe", "<root>"),
        (b"[1, 2, 3]", "<root>"),
        (b'{"seq": 1, "t": 0, "stamp": 0}', "v"),  # no version
        (b'{"v": 2, "seq": 1, "t": 0, "stamp": 0}', "v"),  # unknown version
        (b'{"v": 1, "seq": 1, "t": "0", "stamp": 0}', "t"),  # no string-to-number coercion
        (b'{"v": 1, "seq": 1, "t": NaN, "stamp": 0}', "t"),
        (b'{"v": 1, "seq": 1, "t": 0, "stamp": 0, "giver_face": [1, 2]}', "giver_face"),
        (b'{"v": 1, "seq": 1, "t": 0, "stamp": 0, "load_share": 1.5}', "load_share"),
        (b'{"v": 1, "seq": -1, "t": 0, "stamp": 0}', "seq"),
        (b'{"v": 1, "seq": 1, "t": 0, "stamp": 0, "extra": 1}', "extra"),
    ],
)
def test_malformed_tracking_payload_is_rejected_with_the_field_named(raw, where):
    with pytest.raises(PayloadError) as err:
        TrackingMsg.decode(raw)
    assert where in err.value.reason


def test_head_command_from_engine_command_is_finite_json():
    cmd = GazeCommand(
        t=2.0, phase=Phase.REACH, target="hand", target_point=np.array([0.7, 0.0, 1.0]),
        head={"head_pan": 0.2}, eye_yaw=0.05, eye_pitch=-0.02, residual=0.01,
    )
    msg = HeadCommandMsg.decode(HeadCommandMsg.from_command(cmd, 3, 1.0, answers=9).encode())
    assert msg.head == {"head_pan": 0.2} and msg.phase == "reach" and msg.answers == 9
    with pytest.raises(ValueError):
        HeadCommandMsg(seq=0, t=0, stamp=0, head={"head_pan": math.nan}, phase="idle",
                       target="face")


def test_event_round_trip_restores_engine_events_only():
    ev = Event(EventKind.ROBOT_REACH_STARTED, 1.0, 1.1, {"planned_duration": np.float64(1.5)})
    msg = EventMsg.decode(EventMsg.from_event(ev, "sim", 0, 5.0).encode())
    assert msg.category == "robot" and msg.to_event() == Event(
        EventKind.ROBOT_REACH_STARTED, 1.0, 1.1, {"planned_duration": 1.5})
    fault = EventMsg(seq=1, source="engine", category="fault", kind="tracking_timeout", t=0,
                     detected_at=0, stamp=0)
    assert EventMsg.decode(fault.encode()).to_event() is None
    hist = EventHistoryMsg(node="sim", events=[msg, fault])
    assert EventHistoryMsg.decode(hist.encode()) == hist


def test_arm_command_needs_exactly_one_goal():
    assert ArmCommandMsg(seq=0, t=0, stamp=0, pose="home", gripper=0.0).pose == "home"
    with pytest.raises(PayloadError, match="exactly one"):
        ArmCommandMsg.decode(b'{"v":1,"seq":0,"t":0,"stamp":0,"pose":"home","resume":true}')
    with pytest.raises(PayloadError):
        ArmCommandMsg.decode(b'{"v":1,"seq":0,"t":0,"stamp":0,"pose":"wave"}')


def test_eye_frame_encodes_and_decodes_the_image():
    img = np.zeros((30, 50, 3), np.uint8)
    img[5:10, 20:30] = (255, 0, 0)
    msg = EyeFrameMsg.decode(EyeFrameMsg.from_image(img, 0, 0.0, 0.0, fmt="png").encode())
    assert (msg.width, msg.height) == (50, 30)
    np.testing.assert_array_equal(msg.image(), img)
    bad = msg.model_copy(update={"width": 51})
    with pytest.raises(PayloadError, match="header"):
        bad.image()


def test_status_rejects_unknown_state():
    with pytest.raises(PayloadError):
        StatusMsg.decode(b'{"v":1,"node":"x","seq":0,"stamp":0,"uptime":0,"state":"fine"}')


def test_key_layout_and_bus_config_reject_bad_names():
    keys = KeyLayout("sawyer")
    assert keys.tracking == "gazebot/sawyer/tracking"
    assert keys.head_command == "gazebot/sawyer/head/command"
    assert keys.eyes_frame == "gazebot/sawyer/eyes/frame"
    assert keys.node_of_alive(keys.alive("engine")) == "engine"
    for bad in ("", "a/b", "a*", "x y"):
        with pytest.raises(ValueError, match="robot id"):
            KeyLayout(bad)
    with pytest.raises(ValueError, match="endpoint"):
        BusConfig(listen=("127.0.0.1:7447",))
    with pytest.raises(ValueError, match="router"):
        BusConfig(mode="client", connect=())
    cfg = BusConfig().zenoh_config()
    assert '"tcp/127.0.0.1:7447"' in cfg.get_json("listen/endpoints")
    assert cfg.get_json("scouting/multicast/enabled") == "false"
