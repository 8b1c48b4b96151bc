"""Timing helpers shared by the benchmarks: medians of repeated runs, ratios against a peer."""

from __future__ import annotations

import os
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")


@dataclass(frozen=True)
class Result:
    """One benchmark line: ``ours`` against ``peer`` (both medians, in ``unit``)."""

    name: str
    ours: float
    peer: float | None
    unit: str
    peer_name: str = ""
    higher_is_better: bool = False
    note: str = ""

    @property
    def ratio(self) -> float | None:
        """How many times better ours is than the peer (>1 = ours better)."""
        if self.peer is None or self.ours == 0 or self.peer == 0:
            return None
        return self.ours / self.peer if self.higher_is_better else self.peer / self.ours


def median_time(
    fn: Callable[[], object], repeat: int = 7, number: int = 1, warmup: int = 1
) -> float:
    """Median wall time of ``number`` calls of ``fn`` over ``repeat`` runs, per call (s)."""
    for _ in range(warmup):
        fn()
    samples = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        samples.append((time.perf_counter() - t0) / number)
    return statistics.median(samples)


def best_cpu_time(
    fn: Callable[[], object], repeat: int = 9, number: int = 1, warmup: int = 1
) -> float:
    """Least CPU time of this thread (``time.thread_time``) of ``number`` calls of ``fn`` over
    ``repeat`` runs, per call (s): on a shared machine other processes inflate wall times, the
    CPU time a call takes much less (the least of several runs is the one least disturbed by
    cache and frequency effects of the load)."""
    for _ in range(warmup):
        fn()
    best = float("inf")
    for _ in range(repeat):
        t0 = time.thread_time()
        for _ in range(number):
            fn()
        best = min(best, (time.thread_time() - t0) / number)
    return best


def alternating(
    ours: Callable[[], object], peer: Callable[[], object], rounds: int = 15, number: int = 1
) -> tuple[float, float, float, float]:
    """Wall median and least CPU time (``time.thread_time``) per call of ``ours`` and
    ``peer``, timed in alternating rounds of ``number`` calls each (after one warm-up call
    of each): load from other processes, which comes in bursts longer than a round, then hits
    both alike instead of whichever ran during a burst. Returns ``(ours_wall, peer_wall, ours_cpu,
    peer_cpu)`` in seconds."""
    ours()
    peer()
    wall: dict[int, list[float]] = {0: [], 1: []}
    cpu: dict[int, list[float]] = {0: [], 1: []}
    for i in range(rounds):
        # (the order flips every round: neither always runs right after the other)
        for k in (0, 1) if i % 2 == 0 else (1, 0):
            fn = ours if k == 0 else peer
            w0, c0 = time.perf_counter(), time.thread_time()
            for _ in range(number):
                fn()
            cpu[k].append((time.thread_time() - c0) / number)
            wall[k].append((time.perf_counter() - w0) / number)
    return (
        statistics.median(wall[0]),
        statistics.median(wall[1]),
        min(cpu[0]),
        min(cpu[1]),
    )


def print_results(results: list[Result]) -> None:
    for r in results:
        peer = f"{r.peer:.4g} {r.unit} ({r.peer_name})" if r.peer is not None else "-"
        ratio = f"x{r.ratio:.2f} vs peer" if r.ratio is not None else ""
        note = f"  [{r.note}]" if r.note else ""
        print(f"- {r.name}: {r.ours:.4g} {r.unit} | peer {peer} | {ratio}{note}")


def markdown_rows(results: list[Result]) -> list[str]:
    """``results`` as the rows of a Markdown table (benchmark, ours, peer, ratio, note)."""
    rows = []
    for r in results:
        peer = f"{r.peer:.4g} {r.unit} ({r.peer_name})" if r.peer is not None else "-"
        ratio = f"x{r.ratio:.2f}" if r.ratio is not None else ""
        rows.append(f"| {r.name} | {r.ours:.4g} {r.unit} | {peer} | {ratio} | {r.note} |")
    return rows

