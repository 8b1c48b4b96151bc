"""Tracking samples assembled from their topics (no bus): the parts of one stamp make one
sample, whatever order they arrive in across topics."""

from __future__ import annotations

import pytest
from drivers_fakes import FakeClock

from gazebot.drivers.tracking_assembly import SampleAssembler

ALL = {"giver_hand", "receiver_hand", "giver_face", "gripper", "load_share"}


def parts(t, hand=1.0):
    return [("giver_hand", t, [hand, 0, 1]), ("receiver_hand", t, [0.3, 0, 1]),
            ("giver_face", t, [1.2, 0, 1.6]), ("gripper", t, False), ("load_share", t, 0.0)]


def test_a_sample_is_complete_once_every_published_part_arrived():
    asm = SampleAssembler(lambda: ALL)
    out = [m for p in parts(0.5) for m in asm.add(*p)]
    assert len(out) == 1
    m = out[0]
    assert m.t == 0.5 and m.giver_hand == (1.0, 0.0, 1.0) and m.gripper_closed is False
    assert m.load_share == 0.0 and m.giver_face == (1.2, 0.0, 1.6)


def test_interleaved_topics_do_not_split_samples():
    # topic order is kept, the order across topics is not: the hand runs two samples ahead
    asm = SampleAssembler(lambda: ALL)
    a, b, c = parts(0.1), parts(0.2), parts(0.3)
    out = []
    for p in (a[0], b[0], c[0], *a[1:], *b[1:], *c[1:]):
        out += asm.add(*p)
    assert [m.t for m in out] == pytest.approx([0.1, 0.2, 0.3], abs=1e-9)
    assert all(m.giver_face is not None and m.receiver_hand is not None for m in out)


def test_an_untracked_part_completes_the_sample_once_its_topic_moves_on():
    asm = SampleAssembler(lambda: ALL)
    first = [p for p in parts(0.1) if p[0] != "giver_face"]  # the face is not seen at 0.1
    out = [m for p in first for m in asm.add(*p)]
    assert out == []
    out = asm.add("giver_face", 0.2, [1.2, 0, 1.6])
    assert [m.t for m in out] == [0.1] and out[0].giver_face is None


def test_a_stalled_sample_is_flushed_after_the_timeout_and_late_parts_dropped():
    clock = FakeClock(10.0)
    asm = SampleAssembler(lambda: ALL, timeout=0.05, clock=clock)
    assert asm.add("giver_hand", 1.0, [1, 0, 1]) == []
    assert asm.flush_stale() == []
    clock.now += 0.06
    [m] = asm.flush_stale()
    assert m.t == 1.0 and m.giver_face is None
    assert asm.add("giver_face", 1.0, [1, 0, 1]) == [] and asm.late == 1


def test_a_robot_clock_going_back_starts_a_new_timeline():
    asm = SampleAssembler(lambda: {"giver_hand"})
    assert [m.t for m in asm.add("giver_hand", 5.0, [1, 0, 1])] == [5.0]
    assert [m.t for m in asm.add("giver_hand", 0.0, [1, 0, 1])] == [0.0]
    assert asm.late == 0
