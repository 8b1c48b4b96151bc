"""Tracking samples assembled from their topics (no bus): the parts of one stamp make one
sample, whatever order they arrive in across topics."""

from __future__ import annotations

import pytest
from drivers_fakes import FakeClock

from gazebot.io.drivers.tracking_assembly import SampleAssembler
from gazebot.io.ros2.values import finite_point

ALL = {"giver_hand", "receiver_hand", "giver_face", "gripper", "load_share"}


def parts(t, hand=1.0):
    return [("giver_hand", t, [hand, 0, 1]), ("receiver_hand", t, [0.3, 0, 1]),
            ("giver_face", t, [1.2, 0, 1.6]), ("gripper", t, False), ("load_share", t, 0.0)]


def test_a_sample_is_complete_once_every_published_part_arrived():
    asm = SampleAssembler(lambda: ALL)
    out = [m for p in parts(0.5) for m in asm.add(*p)]
    assert len(out) == 1
    m = out[0]
    assert m.t == 0.5 and finite_point(m.giver_hand) == (1.0, 0.0, 1.0)
    assert m.gripper_closed is False
    assert m.load_share == 0.0 and finite_point(m.giver_face) == (1.2, 0.0, 1.6)


def test_interleaved_topics_do_not_split_samples():
    # topic order is kept, the order across topics is not: the hand runs two samples ahead
    asm = SampleAssembler(lambda: ALL)
    a, b, c = parts(0.1), parts(0.2), parts(0.3)
    out = []
    for p in (a[0], b[0], c[0], *a[1:], *b[1:], *c[1:]):
        out += asm.add(*p)
    assert [m.t for m in out] == pytest.approx([0.1, 0.2, 0.3], abs=1e-9)
    assert all(finite_point(m.giver_face) and finite_point(m.receiver_hand) for m in out)


def test_an_untracked_part_completes_the_sample_once_its_topic_moves_on():
    asm = SampleAssembler(lambda: ALL)
    first = [p for p in parts(0.1) if p[0] != "giver_face"]  # the face is not seen at 0.1
    out = [m for p in first for m in asm.add(*p)]
    assert out == []
    out = asm.add("giver_face", 0.2, [1.2, 0, 1.6])
    assert [m.t for m in out] == [0.1] and finite_point(out[0].giver_face) is None


def test_a_sender_stalling_between_its_puts_does_not_split_a_sample():
    # a busy machine pauses the sender for 0.2 s after its first put: the clock says nothing
    # about completeness, only the stamps do
    clock = FakeClock(10.0)
    asm = SampleAssembler(lambda: ALL, clock=clock)
    first, *rest = parts(1.0)
    assert asm.add(*first) == []
    clock.now += 0.2
    assert asm.flush_stale() == []
    out = [m for p in rest for m in asm.add(*p)]
    assert [m.t for m in out] == [1.0] and finite_point(out[0].giver_face) == (1.2, 0.0, 1.6)
    assert asm.late == 0


def test_a_part_that_stops_being_tracked_is_waited_for_only_the_reorder_window_once():
    # the face has a publisher but is lost from sample 1 on: the sender stops sending it; the
    # clock stands still
    clock = FakeClock(10.0)
    asm = SampleAssembler(lambda: ALL, reorder=3, clock=clock)
    out = [m for p in parts(0.0) for m in asm.add(*p)]
    assert [m.t for m in out] == [0.0] and finite_point(out[0].giver_face) is not None
    for k in range(1, 5):  # sample 1 waits for its face until 3 newer samples arrived
        out += [m for p in parts(k / 10) if p[0] != "giver_face" for m in asm.add(*p)]
        assert len(out) == (1 if k < 4 else 5)
    for k in range(5, 7):  # from there on, a sample is complete when its parts arrived
        out += [m for p in parts(k / 10) if p[0] != "giver_face" for m in asm.add(*p)]
        assert len(out) == k + 1
    assert [round(m.t, 9) for m in out] == [k / 10 for k in range(7)]
    assert all(not finite_point(m.giver_face) and finite_point(m.giver_hand) for m in out[1:])
    # the face is back: the sample carries it, and the next one waits for it again
    out = [m for p in parts(0.7) for m in asm.add(*p)]
    assert [m.t for m in out] == [pytest.approx(0.7)]
    assert finite_point(out[0].giver_face) is not None
    assert asm.add("giver_hand", 0.8, [1, 0, 1]) == []
    assert asm.late == 0


def test_a_part_that_lagged_beyond_the_window_is_waited_for_again():
    asm = SampleAssembler(lambda: {"giver_hand", "giver_face"}, reorder=2)
    asm.add("giver_face", 0.0, [1, 0, 1])
    asm.add("giver_hand", 0.0, [1, 0, 1])
    for k in (1, 2, 3):  # the face lags: sample 0.1 goes without it, and so do the next
        asm.add("giver_hand", k / 10, [1, 0, 1])
    for k in (1, 2, 3):
        assert asm.add("giver_face", k / 10, [1, 0, 1]) == []
    assert asm.late == 3
    # the late face is awaited again: sample 0.4 waits for it
    assert asm.add("giver_hand", 0.4, [1, 0, 1]) == []
    [m] = asm.add("giver_face", 0.4, [1, 0, 1])
    assert m.t == 0.4 and finite_point(m.giver_face) is not None


def test_a_part_the_source_published_before_is_awaited_even_before_the_graph_lists_it():
    # the graph lags: it knows only the hand's publisher, but the face came with sample 0.1
    asm = SampleAssembler(lambda: {"giver_hand"})
    assert asm.add("giver_face", 0.1, [1.2, 0, 1.6]) == []
    assert [m.t for m in asm.add("giver_hand", 0.1, [1, 0, 1])] == [0.1]
    assert asm.add("giver_hand", 0.2, [1, 0, 1]) == []  # the face of 0.2 may still come
    [m] = asm.add("giver_face", 0.2, [1.2, 0, 1.6])
    assert m.t == 0.2 and finite_point(m.giver_face) == (1.2, 0.0, 1.6) and asm.late == 0


def test_pending_samples_are_flushed_after_the_idle_time_and_late_parts_dropped():
    clock = FakeClock(10.0)
    asm = SampleAssembler(lambda: ALL, idle_flush=0.5, clock=clock)
    assert asm.add("giver_hand", 1.0, [1, 0, 1]) == []
    assert asm.next_deadline() == 10.5
    clock.now += 0.49
    assert asm.flush_stale() == []
    clock.now += 0.01
    [m] = asm.flush_stale()
    assert m.t == 1.0 and finite_point(m.giver_face) is None
    assert asm.next_deadline() is None
    assert asm.add("giver_face", 1.0, [1, 0, 1]) == [] and asm.late == 1


def test_the_assembly_refuses_a_non_positive_idle_time_or_window():
    with pytest.raises(ValueError, match="idle_flush"):
        SampleAssembler(lambda: ALL, idle_flush=0.0)
    with pytest.raises(ValueError, match="reorder"):
        SampleAssembler(lambda: ALL, reorder=0)


def test_a_robot_clock_going_back_starts_a_new_timeline():
    asm = SampleAssembler(lambda: {"giver_hand"})
    assert [m.t for m in asm.add("giver_hand", 5.0, [1, 0, 1])] == [5.0]
    assert [m.t for m in asm.add("giver_hand", 0.0, [1, 0, 1])] == [0.0]
    assert asm.late == 0


def test_a_topic_lagging_by_more_than_the_clock_reset_is_late_not_a_restart():
    # the load share's callbacks were starved for 0.6 s while the other topics went on
    asm = SampleAssembler(lambda: {"giver_hand", "load_share"}, reorder=2, clock_reset=0.5)
    asm.add("load_share", 0.0, 0.0)
    asm.add("giver_hand", 0.0, [1, 0, 1])
    for k in range(1, 80):
        asm.add("giver_hand", k / 100, [1, 0, 1])
    assert asm.add("load_share", 0.01, 0.0) == [] and asm.late == 1
    # a topic that itself goes back in time is a restarted clock: the samples start over
    assert asm.add("giver_hand", 0.0, [1, 0, 1]) == [] and asm.late == 1
    [m] = asm.add("load_share", 0.0, 0.0)
    assert m.t == 0.0 and m.load_share == 0.0 and finite_point(m.giver_hand) == (1.0, 0.0, 1.0)
