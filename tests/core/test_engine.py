"""The engine end to end without a simulator: tracking frames in, head and eye commands out."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gazebot import Event, EventKind, GazeEngine, Phase, TrackingFrame
from gazebot.core.minimum_jerk import minimum_jerk


def handover_frames(rate: float = 120.0, seed: int = 0) -> list[TrackingFrame]:
    """A scripted human-to-robot handover: the giver reaches (1.0-2.0 s), both hold the object
    (2.0-2.6 s), the giver retreats (2.6-3.6 s); the gripper reaches a little later and stays."""
    rng = np.random.default_rng(seed)
    face = np.array([1.15, 0.0, 1.6])
    hand_rest = np.array([1.0, -0.35, 0.85])
    meet = np.array([0.7, -0.2, 1.0])
    grip_home = np.array([0.35, 0.0, 0.9])
    grip_meet = meet + np.array([-0.03, 0.0, 0.0])
    frames = []
    for t in np.arange(0.0, 5.0, 1.0 / rate):
        if t < 2.6:
            hand = hand_rest + (meet - hand_rest) * minimum_jerk((t - 1.0) / 1.0)
        else:
            hand = meet + (hand_rest - meet) * minimum_jerk((t - 2.6) / 1.0)
        grip = grip_home + (grip_meet - grip_home) * minimum_jerk((t - 1.2) / 0.9)
        noise = rng.normal(0.0, 0.002, size=(2, 3))
        frames.append(
            TrackingFrame.make(
                t, giver_hand=hand + noise[0], receiver_hand=grip + noise[1], giver_face=face
            )
        )
    return frames


@pytest.fixture(scope="module")
def engine() -> GazeEngine:
    return GazeEngine.from_config(robot="sawyer", behavior="face-hand-face")


def run(engine: GazeEngine, frames: list[TrackingFrame]):
    engine.reset()
    return [engine.step(f) for f in frames]


def _runs(values: list[str]) -> list[str]:
    out: list[str] = []
    for v in values:
        if not out or out[-1] != v:
            out.append(v)
    return out


def test_phases_run_in_order_reach_transfer_retreat(engine):
    commands = run(engine, handover_frames())
    phases = [c.phase for c in commands if c.phase in (Phase.REACH, Phase.TRANSFER, Phase.RETREAT)]
    assert _runs([p.value for p in phases]) == ["reach", "transfer", "retreat"]


def test_face_hand_face_targets_face_then_hand_then_face(engine):
    commands = run(engine, handover_frames())
    assert _runs([c.target for c in commands]) == ["face", "hand", "face"]


def test_every_command_is_finite_and_within_head_limits(engine):
    commands = run(engine, handover_frames())
    lower, upper = engine.robot.lower, engine.robot.upper
    for c in commands:
        assert c.is_finite()
        q = np.array([c.head[j] for j in engine.robot.head_joints])
        assert np.all(q >= lower - 1e-9) and np.all(q <= upper + 1e-9)


def test_head_turns_toward_the_hand_when_the_target_changes(engine):
    commands = run(engine, handover_frames())
    first_hand = next(i for i, c in enumerate(commands) if c.target == "hand")
    settled = commands[min(first_hand + 120, len(commands) - 1)]  # 1 s later
    before = commands[first_hand - 1]
    # Sawyer's head pans; the hand is to the robot's right of the face (y < 0) and lower.
    pan_before, pan_after = before.head["head_pan"], settled.head["head_pan"]
    assert pan_after < pan_before - math.radians(5)
    # The head turned most of the way: the eyes only cover the rest.
    assert abs(settled.eye_yaw) < abs(pan_after - pan_before)
    assert settled.eye_pitch > before.eye_pitch  # looks down toward the hand
    assert settled.residual < math.radians(1.0)


def test_missing_tracking_never_produces_a_non_finite_command(engine):
    frames = handover_frames()
    holey = [
        TrackingFrame.make(f.t) if 150 <= i < 200 else f  # 0.4 s with no tracking at all
        for i, f in enumerate(frames)
    ]
    for c in run(engine, holey):
        assert c.is_finite()
        assert np.all(np.isfinite(c.target_point))


def test_out_of_order_frames_do_not_move_time_backwards(engine):
    frames = handover_frames()
    shuffled = frames[:300] + [frames[100], frames[50]] + frames[300:]
    commands = run(engine, shuffled)
    ts = [c.t for c in commands]
    assert all(b >= a for a, b in zip(ts, ts[1:], strict=False))
    assert all(c.is_finite() for c in commands)


def test_resync_after_restart_resumes_the_handover_phase(engine):
    frames = handover_frames()
    commands = run(engine, frames[:290])  # into the transfer (t ~ 2.42 s)
    assert commands[-1].phase == Phase.TRANSFER
    published = [e for c in commands for e in c.events]
    fresh = GazeEngine.from_config(robot="sawyer", behavior="face-hand-face")
    fresh.resync(published)
    cmd = fresh.step(frames[290])
    assert cmd.phase == Phase.TRANSFER
    assert cmd.target == "hand"


def test_robot_events_reach_the_behavior(engine):
    long_fh = GazeEngine.from_config(robot="sawyer", behavior="long-face-hand")
    frames = handover_frames()
    commands = []
    for f in frames:
        if abs(f.t - 1.2) < 1e-9:
            long_fh.notify(
                Event(EventKind.ROBOT_REACH_STARTED, f.t, f.t, {"planned_duration": 0.9})
            )
        if abs(f.t - 2.1) < 1e-9:
            long_fh.notify(Event(EventKind.ROBOT_REACH_ENDED, f.t, f.t))
        commands.append(long_fh.step(f))
    first_hand = next(c.t for c in commands if c.target == "hand")
    assert 2.1 - 1e-6 <= first_hand < 2.2


def test_behavior_naming_a_point_the_robot_lacks_is_rejected_with_file_and_field(tmp_path):
    from gazebot.core.config import ConfigError

    path = tmp_path / "look-at-lamp.yaml"
    path.write_text(
        "segments:\n"
        "  - {phase: reach, at: 0.0, target: face}\n"
        "  - {phase: transfer, at: 0.0, target: lamp}\n"
    )
    with pytest.raises(ConfigError) as err:
        GazeEngine.from_config(robot="sawyer", behavior=path)
    assert "targets" in str(err.value) and "lamp" in str(err.value)


def test_example_user_behavior_runs_and_looks_at_the_dropoff_point():
    from pathlib import Path

    example = Path(__file__).resolve().parents[2] / "examples" / "look-at-dropoff.yaml"
    eng = GazeEngine.from_config(robot="sawyer", behavior=example)
    frames = handover_frames()
    targets = []
    for f in frames:
        if abs(f.t - 2.7) < 1e-9:
            eng.notify(Event(EventKind.ROBOT_RETREAT_STARTED, f.t, f.t, {"planned_duration": 1.0}))
        targets.append(eng.step(f).target)
    assert _runs(targets)[:3] == ["face", "hand", "dropoff"]


def test_sawyer_head_pan_compensates_the_arm_joint_that_carries_the_head():
    frames = [TrackingFrame.make(t, giver_face=[1.1, 0.3, 1.6]) for t in np.arange(0, 3, 1 / 120)]
    plain = GazeEngine.from_config(robot="sawyer", behavior="face")
    turned = GazeEngine.from_config(robot="sawyer", behavior="face")
    a = [plain.step(f, arm={"right_j0": 0.0}) for f in frames][-1]
    b = [turned.step(f, arm={"right_j0": 0.4}) for f in frames][-1]
    assert a.residual < math.radians(0.5) and b.residual < math.radians(0.5)
    assert b.head["head_pan"] == pytest.approx(a.head["head_pan"] - 0.4, abs=math.radians(0.5))


def test_frame_without_a_usable_time_is_answered_at_the_last_known_time(engine):
    engine.reset()
    first = engine.step(TrackingFrame.make(float("nan"), giver_face=[1.1, 0.0, 1.6]))
    assert first.t == 0.0 and first.is_finite()
    engine.step(TrackingFrame.make(0.5, giver_face=[1.1, 0.0, 1.6]))
    later = engine.step(TrackingFrame.make(float("nan"), giver_face=[1.1, 0.0, 1.6]))
    assert later.t == 0.5 and later.is_finite()


def test_a_sample_revealing_several_phase_events_delivers_them_all_at_once():
    # No reach was seen (tracking starts with the hands together), then the gripper closes:
    # that one sample reveals both the reach and the transfer.
    eng = GazeEngine.from_config(robot="sawyer", behavior="face-hand-face")
    kinds = []
    for t in np.arange(0.0, 1.0, 1 / 120):
        frame = TrackingFrame.make(
            t,
            giver_hand=[0.7, 0.0, 1.0],
            receiver_hand=[0.66, 0.0, 1.0],
            giver_face=[1.1, 0.0, 1.6],
            gripper_closed=t >= 0.5,
            load_share=0.5 if t >= 0.5 else 0.0,
        )
        cmd = eng.step(frame)
        kinds += [(round(t, 3), e.kind.value) for e in cmd.events]
    assert [k for _, k in kinds] == ["reach_started", "transfer_started"]
    assert kinds[0][0] == kinds[1][0]
    assert cmd.phase == Phase.TRANSFER and cmd.target == "hand"


def test_look_at_points_the_real_head_and_eyes_at_a_fixed_point_keeping_the_phase(engine):
    engine.reset()
    frames = handover_frames()
    for f in frames[: int(1.5 * 120)]:  # into the reach
        engine.step(f)
    phase = engine.phase
    assert phase is Phase.REACH
    point = np.array([1.0, 0.6, 1.2])  # to the robot's left
    t0 = frames[int(1.5 * 120) - 1].t
    cmds = [engine.look_at(t0 + i / 120, point, target="dropoff") for i in range(1, 3 * 120)]
    last = cmds[-1]
    assert all(c.is_finite() for c in cmds)
    assert last.target == "dropoff" and last.phase is phase and engine.phase is phase
    np.testing.assert_allclose(last.target_point, point)
    # the gaze shift takes time (timing and limits apply), then the line of sight is on it
    assert cmds[0].residual > math.radians(5)
    assert last.residual < math.radians(1.0)
    lo, hi = engine.robot.lower, engine.robot.upper
    for c in cmds:
        q = engine.robot.head_vector(c.head)
        assert np.all(q >= lo - 1e-9) and np.all(q <= hi + 1e-9)
    assert last.head["head_pan"] > cmds[0].head["head_pan"]  # turned toward the left
    # a time going back is answered at the last time, never earlier
    assert engine.look_at(t0, point).t == last.t
    assert engine.look_at(math.nan, point).t == last.t


@pytest.mark.parametrize("behavior", ["face-hand-face", "short-face-hand"])
def test_a_robot_first_reach_is_reported_as_the_reach_from_the_first_look_at_the_hand(behavior):
    # Issue 19: robot_reach_started at 0.5 s, the giver's hand still. The phase the command
    # reports is the phase the behavior runs: reach (decided by the robot) from the first
    # command that looks at the hand (was: idle with target hand from 1.00 to 1.74 s).
    eng = GazeEngine.from_config(robot="sawyer", behavior=behavior)
    hand, grip, face = [1.0, -0.35, 0.85], [0.35, 0.0, 0.9], [1.15, 0.0, 1.6]
    commands = []
    for t in np.arange(0.0, 3.0, 1 / 120):
        if abs(t - 0.5) < 1e-9:
            eng.notify(Event(EventKind.ROBOT_REACH_STARTED, t, t, {"planned_duration": 1.0}))
        commands.append(
            eng.step(TrackingFrame.make(t, giver_hand=hand, receiver_hand=grip, giver_face=face))
        )
    on_hand = [c for c in commands if c.target == "hand"]
    assert on_hand and on_hand[0].t >= 0.5, "the behavior looks at the hand before the reach"
    assert all(c.phase is Phase.REACH and c.phase_source == "robot" for c in on_hand)
    assert all(c.phase is Phase.IDLE for c in commands if c.t < 0.5)
    assert all(c.phase is Phase.REACH for c in commands if c.t >= 0.5)


def test_the_command_reports_the_gripper_as_the_source_of_a_grasped_transfer():
    eng = GazeEngine.from_config(robot="sawyer", behavior="face-hand-face")
    eng.notify(Event(EventKind.ROBOT_REACH_STARTED, 0.1, 0.1, {"planned_duration": 1.0}))
    eng.step(TrackingFrame.make(0.1))
    eng.notify([Event(EventKind.ROBOT_GRASPED, 0.2, 0.2)])  # one event or many
    cmd = eng.step(TrackingFrame.make(0.2))
    assert (cmd.phase, cmd.phase_source) == (Phase.TRANSFER, "gripper")
    # The detector keeps no phase: it follows the state's transfer (it cannot see a grasp).
    assert not hasattr(eng.detector, "phase")
    assert eng.detector.expected_end(eng.handover) >= 0.2


def test_an_earlier_giver_reach_told_late_takes_the_source_without_a_second_reach_event():
    # Review finding 10a: the commands report the reach's revised start and source when the
    # giver's earlier reach arrives after the robot's; the phase stream keeps one reach event.
    eng = GazeEngine.from_config(robot="sawyer", behavior="face-hand-face")
    eng.notify(Event(EventKind.ROBOT_REACH_STARTED, 0.8, 0.8, {"planned_duration": 1.0}))
    first = eng.step(TrackingFrame.make(0.8))
    reach = [e for e in first.events if e.kind is EventKind.REACH_STARTED]
    assert [(e.t, e.info["source"]) for e in reach] == [(0.8, "robot")]
    assert (first.phase, first.phase_source) == (Phase.REACH, "robot")
    eng.notify(Event(EventKind.REACH_STARTED, 0.5, 0.85))
    cmd = eng.step(TrackingFrame.make(0.85))
    assert (cmd.phase, cmd.phase_source, eng.handover.phase_start) == (Phase.REACH, "tracking", 0.5)
    assert not [e for e in cmd.events if e.kind is EventKind.REACH_STARTED]


def test_the_phase_has_one_owner_the_handover_state():
    # Issue 31: no stage keeps a phase of its own; the state's machine holds it.
    eng = GazeEngine.from_config(robot="sawyer", behavior="face-hand-face")
    eng.notify(Event(EventKind.ROBOT_REACH_STARTED, 0.1, 0.1, {"planned_duration": 1.0}))
    eng.step(TrackingFrame.make(0.1))
    eng.notify(Event(EventKind.ROBOT_GRASPED, 0.2, 0.2))
    cmd = eng.step(TrackingFrame.make(0.2))
    for stage in (eng, eng.detector, eng.behavior, eng.handover):
        assert not [k for k, v in vars(stage).items() if isinstance(v, Phase)], stage
    assert cmd.phase is eng.phase is eng.behavior.phase is eng.handover.phase is Phase.TRANSFER
