"""One stream per publisher GID (:mod:`gazebot.io.drivers.streams`), on a clock the tests
move: a GID whose numbers go back carries a copy and is refused, both streams, until ``hold``
seconds after its numbers last went back."""

from __future__ import annotations

from drivers_fakes import FakeClock as Clock

from gazebot.io.drivers.streams import SequenceGuard

A, B = b"a" * 16, b"b" * 16


def test_numbers_going_forward_are_one_stream_even_with_gaps():
    guard = SequenceGuard(1.0, Clock())
    assert [guard.check(A, seq) for seq in (1, 2, 5, 6, 100)] == [None] * 5


def test_numbers_going_back_refuse_both_streams_while_the_copy_lasts():
    clock = Clock()
    guard = SequenceGuard(1.0, clock)
    for seq in range(1, 11):
        assert guard.check(A, seq) is None
    assert "second stream" in guard.check(A, 3)  # the copy starts below the publisher
    clock.now = 0.5
    assert guard.check(A, 11) is not None  # the publisher's own next sample: refused too
    assert guard.check(A, 4) is not None  # the copy, interleaved: goes back again
    clock.now = 1.4  # 0.9 s after the last step back
    assert guard.check(A, 12) is not None
    assert guard.check(B, 1) is None  # other GIDs are not touched


def test_a_gid_is_used_again_once_its_numbers_went_forward_for_the_hold():
    clock = Clock()
    guard = SequenceGuard(1.0, clock)
    guard.check(A, 10)
    guard.check(A, 2)
    for k in range(1, 120):  # the copy is gone; the publisher goes on at 120 Hz
        clock.now = k / 120
        assert guard.check(A, 10 + k) is not None
    clock.now = 1.0
    assert guard.check(A, 130) is None
    assert guard.check(A, 131) is None


def test_a_copy_running_alone_past_the_hold_is_taken():
    # The documented limit: numbers go back only when the streams interleave, so a copy that
    # arrives on its own more than ``hold`` after the publisher's last sample is used.
    clock = Clock()
    guard = SequenceGuard(1.0, clock)
    guard.check(A, 50)
    guard.check(A, 1)  # the copy
    clock.now = 1.01
    assert guard.check(A, 2) is None


def test_a_publisher_gone_is_forgotten():
    guard = SequenceGuard(1.0, Clock())
    guard.check(A, 50)
    guard.check(A, 1)
    guard.forget(A)  # its liveliness token went away: a new publisher may get the GID
    assert guard.check(A, 1) is None
