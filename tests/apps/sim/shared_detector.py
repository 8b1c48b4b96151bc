"""One phase detector shared by several runtime loops fed the same frames and events (its
answer to each sample replayed to the others): the tests that tick every seed behavior at once."""

from __future__ import annotations

import math


class SharedDetector:
    """The first loop's phase detector; the other loops get its answer to each sample (it reads
    the frames and its loop's handover state, which every loop's equals: the same frames and
    events; and it costs most of a tick)."""

    def __init__(self, detector) -> None:
        self._detector = detector
        self.last: list = []
        self.end = math.nan

    def update(self, frame, view, report) -> None:
        self.last = []

        def keep(event) -> None:
            self.last.append(event)
            report(event)

        self._detector.update(frame, view, keep)

    def expected_end(self, view) -> float:
        self.end = self._detector.expected_end(view)
        return self.end

    def __getattr__(self, name):
        return getattr(self._detector, name)


class Replay:
    """Stands in for a further loop's detector: the shared detector's answer to this sample."""

    def __init__(self, shared: SharedDetector) -> None:
        self._shared = shared

    def update(self, frame, view, report) -> None:
        for event in self._shared.last:
            report(event)

    def expected_end(self, view) -> float:
        return self._shared.end

    def __getattr__(self, name):
        return getattr(self._shared, name)
