"""Frames and eye state for a real head screen: JPEG/PNG bytes and the EyeState JSON."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from gazebot.render import EyeRenderer, EyeState, decode_frame, encode_frame


@pytest.fixture(scope="module")
def frame() -> np.ndarray:
    return EyeRenderer(320, 188, "cartoon").render(0.2, 0.1, 0.2)


def test_png_round_trip_is_lossless_and_keeps_rgb_order(frame):
    data = encode_frame(frame, "png")
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert np.array_equal(decode_frame(data), frame)


def test_jpeg_round_trip_is_close_and_quality_trades_size(frame):
    hi = encode_frame(frame, "jpeg", quality=95)
    lo = encode_frame(frame, "jpeg", quality=30)
    assert hi[:2] == b"\xff\xd8"
    assert len(lo) < len(hi)
    back = decode_frame(hi).astype(int)
    assert np.abs(back - frame).mean() < 3.0
    # Colors stay in RGB order (a BGR swap would move this mean a lot).
    assert np.abs(back.mean(axis=(0, 1)) - frame.mean(axis=(0, 1))).max() < 2.0


@pytest.mark.parametrize(
    "args,match",
    [
        ((np.zeros((4, 4, 3), np.uint8), "gif"), "fmt"),
        ((np.zeros((4, 4, 3), np.float32), "png"), "uint8"),
        ((np.zeros((4, 4, 4), np.uint8), "png"), "shape"),
    ],
)
def test_encode_bad_inputs_raise_value_error(args, match):
    with pytest.raises(ValueError, match=match):
        encode_frame(*args)


def test_encode_bad_quality_and_decode_garbage_raise_value_error(frame):
    with pytest.raises(ValueError, match="quality"):
        encode_frame(frame, "jpeg", quality=0)
    with pytest.raises(ValueError, match="not a JPEG or PNG"):
        decode_frame(b"hello")


def test_eye_state_json_round_trip():
    s = EyeState(t=1.5, eye_yaw=0.2, eye_pitch=-0.1, blink=0.4, distance=0.8, robot="sawyer")
    text = s.to_json()
    assert json.loads(text)["eye_yaw"] == 0.2
    assert EyeState.from_json(text) == s
    assert EyeState.from_json(text.encode()) == s
    far = EyeState(t=0.0, eye_yaw=0.0, eye_pitch=0.0, distance=math.inf)
    assert json.loads(far.to_json())["distance"] is None


@pytest.mark.parametrize(
    "kwargs",
    [
        {"t": 0.0, "eye_yaw": math.nan, "eye_pitch": 0.0},
        {"t": 0.0, "eye_yaw": 0.0, "eye_pitch": 0.0, "blink": 1.5},
        {"t": 0.0, "eye_yaw": 0.0, "eye_pitch": 0.0, "distance": 0.0},
        {"t": 0.0, "eye_yaw": "0", "eye_pitch": 0.0},
    ],
)
def test_eye_state_rejects_bad_values(kwargs):
    with pytest.raises(ValueError, match="EyeState"):
        EyeState(**kwargs)


@pytest.mark.parametrize(
    "text",
    ["not json", "[1, 2]", '{"t": 0, "eye_yaw": 0}', '{"t":0,"eye_yaw":0,"eye_pitch":0,"x":1}'],
)
def test_eye_state_from_bad_json_raises_value_error(text):
    with pytest.raises(ValueError, match="EyeState"):
        EyeState.from_json(text)
