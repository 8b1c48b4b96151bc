"""A node never dies on input (issue 21): implausible and huge samples are missing samples,
whatever a sample or an event makes a stage raise is reported and survived, and no command
ever carries a non-finite or out-of-limit joint value."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gazebot import Event, EventKind, GazeEngine, TrackingFrame
from gazebot.core.runtime import GazeLoop

FACE, HAND, GRIP = [1.15, 0.0, 1.6], [1.0, -0.35, 0.85], [0.35, 0.0, 0.9]


@pytest.fixture(scope="module")
def loop() -> GazeLoop:
    return GazeLoop.from_config("sawyer", "face-hand-face")


def _safe(engine: GazeEngine, cmd) -> None:
    assert cmd is not None and cmd.is_finite()
    q = engine.robot.head_vector(cmd.head)
    assert np.all(q >= engine.robot.lower - 1e-9) and np.all(q <= engine.robot.upper + 1e-9)
    lo_y, hi_y = engine.robot.eyes.yaw_range
    lo_p, hi_p = engine.robot.eyes.pitch_range
    assert lo_y - 1e-9 <= cmd.eye_yaw <= hi_y + 1e-9 and lo_p - 1e-9 <= cmd.eye_pitch <= hi_p + 1e-9


def test_points_beyond_the_workspace_are_missing_samples_and_counted(loop):
    loop.reset()
    engine = loop.engine
    radius = engine.robot.config.workspace_radius_m
    far = [radius + 1.0, 0.0, 1.0]
    for i in range(60):
        loop.tick(TrackingFrame.make(i / 120, giver_hand=HAND, receiver_hand=GRIP, giver_face=FACE))
    for i in range(60, 120):
        cmd = loop.tick(TrackingFrame.make(i / 120, giver_hand=HAND, receiver_hand=GRIP,
                                           giver_face=far))
        _safe(engine, cmd)
        # The face the gaze is on stays the last plausible one.
        np.testing.assert_allclose(cmd.target_point, FACE)
    assert engine.stats.implausible == 60 and cmd.status == "ok"


def test_each_point_is_judged_on_its_own_whatever_its_float_type(loop):
    """A frame off the usual path (a float32 point beside a far one) keeps its plausible
    points as they are and drops only the far one."""
    engine = loop.engine
    engine.reset()
    radius = engine.robot.config.workspace_radius_m
    grip32 = np.array(GRIP, dtype=np.float32)
    frame = TrackingFrame(t=0.0, giver_hand=np.array(HAND), receiver_hand=grip32,
                          giver_face=np.array([0.0, radius + 1.0, 0.0]))
    kept = engine._plausible(frame)
    assert kept.giver_hand is frame.giver_hand and kept.receiver_hand is grip32
    assert np.all(np.isnan(kept.giver_face)) and engine.stats.implausible == 1
    usual = TrackingFrame(t=0.0, giver_hand=np.array(HAND), receiver_hand=np.array(GRIP),
                          giver_face=np.full(3, np.nan))
    assert engine._plausible(usual) is usual and engine.stats.implausible == 1


@pytest.mark.parametrize("huge", [1e155, -1e308, 1e20])
def test_a_sample_with_huge_finite_values_does_not_kill_the_loop(loop, huge):
    loop.reset()
    for i in range(30):
        loop.tick(TrackingFrame.make(i / 120, giver_hand=HAND, receiver_hand=GRIP, giver_face=FACE))
    bad = TrackingFrame.make(30 / 120, giver_hand=[huge, huge, huge], receiver_hand=GRIP,
                             giver_face=[huge, 0.0, huge])
    cmd = loop.tick(bad)
    _safe(loop.engine, cmd)
    assert loop.engine.stats.implausible == 2
    _safe(loop.engine, loop.tick(TrackingFrame.make(31 / 120, giver_face=FACE)))


class _Exploding:
    """A phase detector that raises on every sample (a bug a sample triggers)."""

    def update(self, frame, view, report):
        raise ZeroDivisionError("boom")

    def expected_end(self, view):
        return math.nan

    def resync(self):
        pass


def test_a_stage_raising_on_a_sample_is_reported_as_a_fault_and_the_engine_goes_on():
    engine = GazeEngine.from_config("sawyer", "face-hand-face")
    engine.step(TrackingFrame.make(0.0, giver_face=FACE))
    engine.detector = _Exploding()
    cmd = engine.step(TrackingFrame.make(0.1, giver_face=FACE))
    _safe(engine, cmd)
    assert cmd.status == "degraded" and engine.stats.faults == 1
    [fault] = [e for e in cmd.events if e.kind is EventKind.FAULT]
    assert fault.info["stage"] == "phases" and "ZeroDivisionError: boom" in fault.info["error"]
    engine.detector = GazeEngine.from_config("sawyer", "face").detector
    assert engine.step(TrackingFrame.make(0.2, giver_face=FACE)).status == "ok"


def test_malformed_events_and_evidence_never_raise():
    engine = GazeEngine.from_config("sawyer", "long-face-hand")
    engine.notify([
        Event(EventKind.ROBOT_REACH_STARTED, 0.1, 0.1, {"planned_duration": "soon"}),
        Event(EventKind.ROBOT_REACH_ENDED, math.inf, math.nan),
        Event("nonsense", 0.1, 0.1),  # type: ignore[arg-type]
        Event(EventKind.REACH_STARTED, 0.1, 0.1, None),  # type: ignore[arg-type]
    ])
    cmd = engine.step(TrackingFrame.make(0.1, giver_face=FACE))
    _safe(engine, cmd)
    frame = TrackingFrame(t=0.2, giver_face=np.array(FACE), gripper_closed=True,
                          load_share="half")  # type: ignore[arg-type]
    cmd = engine.step(frame)
    _safe(engine, cmd)


def test_a_loop_around_an_engine_that_raises_sends_nothing_and_counts_it(loop):
    class Raising:
        robot = loop.engine.robot
        phase = None

        def step(self, frame, arm=None):
            raise RuntimeError("engine bug")

    broken = GazeLoop(Raising())  # type: ignore[arg-type]
    assert broken.tick(TrackingFrame.make(0.0)) is None and broken.faults == 1


def test_tick_rejects_a_time_that_disagrees_with_the_frames(loop):
    with pytest.raises(ValueError, match="disagrees"):
        loop.tick(TrackingFrame.make(1.0), t=2.0)
    with pytest.raises(ValueError, match="needs the robot time"):
        loop.tick(None)
    assert loop.tick(TrackingFrame.make(1.0), t=1.0) is not None


coord = st.one_of(
    st.floats(-2.0, 2.0),
    st.sampled_from([math.nan, math.inf, -math.inf, 1e155, -1e308, 5e3, 0.0]),
)
point = st.one_of(st.none(), st.tuples(coord, coord, coord))
frames = st.lists(
    st.tuples(
        st.one_of(st.floats(0.0, 0.02), st.sampled_from([math.nan, -1.0, 0.0])),  # time step
        point, point, point,
        st.sampled_from([None, True, False]),
        st.one_of(st.none(), st.floats(0.0, 1.0), st.sampled_from([math.nan, 1e155])),
    ),
    min_size=1, max_size=60,
)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow],
          derandomize=True)
@given(script=frames)
def test_no_input_gives_a_non_finite_or_out_of_limit_command(loop, script):
    loop.reset()
    t = 0.0
    for dt, hand, receiver, face, grip, load in script:
        t = t + dt if math.isfinite(dt) and dt >= 0 else dt
        frame = TrackingFrame.make(t if math.isfinite(t) else math.nan, hand, receiver, face,
                                   gripper_closed=grip, load_share=load)
        if not math.isfinite(t):
            t = 0.0
        _safe(loop.engine, loop.tick(frame))
