"""The render progress bar: starts at 0 of the estimated frames, shows ``n/total frame`` all the
way (tqdm drops a total the count passes and prints "238frame"), ends at n/n."""

from __future__ import annotations

import io
import re

from gazebot.apps.render.progress import FrameProgress

PAIR = re.compile(r"(\d+)/(\d+) ?\[")


def _pairs(text: str) -> list[tuple[int, int]]:
    return [(int(a), int(b)) for a, b in PAIR.findall(text)]


def _drive(estimate_s: float, frames: int, end_s: float | None) -> str:
    buf = io.StringIO()
    with FrameProgress(10.0, estimate_s, desc="x", file=buf) as bar:
        bar.bar.mininterval = 0  # draw every update
        bar.bar.miniters = 1
        for k in range(frames):
            known = end_s if end_s is not None and k >= frames // 2 else None
            bar.advance(known)
            assert bar.n <= bar.total
        bar.finish()
        assert bar.n == bar.total == frames
    return buf.getvalue()


def test_an_estimate_too_short_never_lets_the_count_pass_the_total():
    out = _drive(estimate_s=2.0, frames=43, end_s=None)  # 21 frames guessed, 43 written
    pairs = _pairs(out)
    assert pairs[0] == (0, 21) and pairs[-1] == (43, 43)
    assert all(n <= total for n, total in pairs)
    assert not re.search(r"\d+ ?frame \[", out)  # tqdm's no-total format
    assert " frame/s" in out


def test_the_known_end_sets_the_total_and_an_estimate_too_long_ends_at_n_of_n():
    out = _drive(estimate_s=6.0, frames=30, end_s=2.9)  # 61 guessed; the end at 2.9 s: 30
    pairs = _pairs(out)
    assert pairs[0] == (0, 61) and pairs[-1] == (30, 30)
    assert (16, 30) in pairs  # once the end is known, the total is exact
