"""No phantom handover after ``handover_done`` (issue 30, item 3).

Over the bus on a busy machine the engine saw, 0.55 s after ``handover_done`` and with both
hands' tracking briefly lost, ``reach_started``, ``transfer_started`` (source ``gripper``) and
``retreat_started`` within 8 ms: a second handover while the robot simply kept holding the
object it had taken. The bus produces samples that carry no robot evidence while the gripper
stays closed: the engine node's silence ticks (no sample arrived for ``silence_after``: the loop
ticks with a bare frame) and samples the assembler completed without their gripper and load-share
parts (those topics' callbacks starved). Such a sample says nothing about the gripper; the next
sample that carries the closed gripper again is no grasp.

These feed the engine (through the runtime loop, as the engine node does) what the bus can
deliver around ``handover_done``: silences, tracking lost and restored, bursts whose older
samples come after a silence tick answered a later time, samples missing their gripper part,
and a late robot event.
"""

from __future__ import annotations

import numpy as np
import pytest

from gazebot import Event, EventKind, Phase, TrackingFrame
from gazebot.core.runtime import GazeLoop
from tests.core.test_engine import handover_frames

RATE = 120.0
GRASP, BOTH_HOLD_END = 2.1, 2.6  # the gripper closes; the giver lets go (share 0.5 -> 1)
PHASE_KINDS = {EventKind.REACH_STARTED, EventKind.TRANSFER_STARTED,
               EventKind.RETREAT_STARTED, EventKind.HANDOVER_DONE}


def _with_robot(frame: TrackingFrame, evidence: bool = True) -> TrackingFrame:
    """``frame`` with the robot's gripper and load share of a human-to-robot handover (the robot
    keeps the object it took: closed, share 1 after the giver let go); ``evidence`` False: the
    sample as assembled without its gripper and load-share parts."""
    t = float(frame.t)
    share = 0.0 if t < GRASP else (0.5 if t < BOTH_HOLD_END else 1.0)
    return TrackingFrame.make(
        t,
        giver_hand=frame.giver_hand,
        receiver_hand=frame.receiver_hand,
        giver_face=frame.giver_face,
        gripper_closed=(t >= GRASP) if evidence else None,
        load_share=share if evidence else None,
    )


def _without_hands(frame: TrackingFrame) -> TrackingFrame:
    return TrackingFrame.make(frame.t, giver_face=frame.giver_face,
                              gripper_closed=frame.gripper_closed, load_share=frame.load_share)


@pytest.fixture(scope="module")
def loop() -> GazeLoop:
    return GazeLoop.from_config(robot="sawyer", behavior="face-hand-face")


def _drive(loop: GazeLoop, disturb) -> list[tuple[float, Event]]:
    """Run the handover (until 6 s: the giver is back at rest from 3.6 s), calling
    ``disturb(loop, frames, i)`` once, 0.3 s after ``handover_done`` was published, with the
    index of the next frame; it returns the index to go on from. Every phase event published,
    with the robot time of the tick that published it."""
    loop.reset()
    frames = [_with_robot(f) for f in handover_frames(RATE)]
    t_last = frames[-1].t
    frames += [_with_robot(TrackingFrame.make(t, giver_hand=frames[-1].giver_hand,
                                              receiver_hand=frames[-1].receiver_hand,
                                              giver_face=frames[-1].giver_face))
               for t in np.arange(t_last + 1 / RATE, 6.0, 1 / RATE)]
    published: list[tuple[float, Event]] = []
    done_at = None
    i = 0
    while i < len(frames):
        cmd = loop.tick(frames[i])
        i += 1
        assert cmd is not None
        published += [(cmd.t, e) for e in cmd.events if e.kind in PHASE_KINDS]
        if done_at is None and any(e.kind is EventKind.HANDOVER_DONE for _, e in published):
            done_at = cmd.t
        if done_at is not None and cmd.t >= done_at + 0.3 and disturb is not None:
            i, disturb = disturb(loop, frames, i, published), None
    assert done_at is not None, "the handover never ended: the scenario is broken"
    return published


def _silence(loop: GazeLoop, t: float, published) -> None:
    """A silence tick of the engine node at robot time ``t`` (no sample arrived)."""
    cmd = loop.tick(None, t=t)
    assert cmd is not None
    published += [(cmd.t, e) for e in cmd.events if e.kind in PHASE_KINDS]


def _one_silence_then_burst(loop, frames, i, published):
    # The bus stalls 0.15 s: one silence tick; then the samples held up arrive in a burst
    # (those older than the tick are too late and dropped), the gripper still closed.
    _silence(loop, frames[i - 1].t + 0.15, published)
    return i


def _lost_and_restored(loop, frames, i, published):
    # A longer stall: silence ticks at 30 Hz until tracking is lost (max_gap_hold), then the
    # burst restores it.
    t0 = frames[i - 1].t
    for k in range(10):
        _silence(loop, t0 + 0.15 + k / 30.0, published)
    return i


def _hands_lost_around_done(loop, frames, i, published):
    # Both hands untracked (the parts not published) for 0.4 s, a silence tick in it, then
    # back.
    end = frames[i].t + 0.4
    while frames[i].t < end:
        cmd = loop.tick(_without_hands(frames[i]))
        published += [(cmd.t, e) for e in cmd.events if e.kind in PHASE_KINDS]
        i += 1
    _silence(loop, frames[i - 1].t + 0.15, published)
    return i


def _gripper_parts_missing(loop, frames, i, published):
    # The gripper and load-share topics starve: the assembler completes 30 samples without
    # those parts; then they arrive again (closed, share 1). A late copy of the finished
    # handover's grasp comes meanwhile.
    for _ in range(30):
        cmd = loop.tick(_with_robot(frames[i], evidence=False))
        published += [(cmd.t, e) for e in cmd.events if e.kind in PHASE_KINDS]
        i += 1
    loop.notify(Event(EventKind.ROBOT_GRASPED, GRASP, frames[i].t, {}))
    return i


@pytest.mark.parametrize(
    "disturb",
    [None, _one_silence_then_burst, _lost_and_restored, _hands_lost_around_done,
     _gripper_parts_missing],
    ids=["undisturbed", "silence-then-burst", "lost-and-restored", "hands-lost",
         "gripper-parts-missing"],
)
def test_a_gripper_that_stays_closed_after_handover_done_starts_no_second_handover(loop, disturb):
    published = _drive(loop, disturb)
    kinds = [e.kind for _, e in published]
    assert kinds == [EventKind.REACH_STARTED, EventKind.TRANSFER_STARTED,
                     EventKind.RETREAT_STARTED, EventKind.HANDOVER_DONE], [
        (round(t, 3), e.kind.value, e.info) for t, e in published]
    assert {e.info.get("handover") for _, e in published} == {0}
    assert loop.phase is Phase.DONE


def _put_down_then_grasp_again(loop, frames, i, published):
    # The robot puts the object down (gripper open, share 0) for 0.1 s, the bus stalls (a
    # silence tick, samples without their gripper part), then the gripper closes again: a real
    # grasp, which the gaps must not hide.
    for k in range(i, len(frames)):
        f = frames[k]
        t = f.t - frames[i].t
        closed = t >= 0.4
        frames[k] = TrackingFrame.make(f.t, giver_hand=f.giver_hand,
                                       receiver_hand=f.receiver_hand, giver_face=f.giver_face,
                                       gripper_closed=closed if not 0.1 <= t < 0.3 else None,
                                       load_share=(0.5 if closed else 0.0)
                                       if not 0.1 <= t < 0.3 else None)
    return i


def test_a_gripper_seen_open_after_handover_done_closes_on_a_new_grasp(loop):
    published = _drive(loop, _put_down_then_grasp_again)
    kinds = [(e.kind, e.info.get("handover")) for _, e in published]
    assert kinds[4:] == [(EventKind.REACH_STARTED, 1), (EventKind.TRANSFER_STARTED, 1)]
    assert published[5][1].info["source"] == "gripper"
    assert loop.phase is Phase.TRANSFER
