"""The progress bar of a video render: frames, with a total that follows the estimated end.

tqdm drops a total the count has passed and then glues the unit to the count ("238frame"); a
total fixed at the start is a guess (how long a handover runs is known only once it ends). So
the total is raised to the current estimate of the end before each frame and set to the frame
count at the end: the bar starts at 0/N, never runs past N, and ends at n/n.
"""

from __future__ import annotations

import math
from typing import Any, TextIO


class FrameProgress:
    """A context manager around one tqdm bar over the frames of a video at ``fps``.

    ``end_s``: the first estimate of the video's end (s); ``enabled``: False draws nothing;
    ``file``: where the bar is drawn (default: stderr).
    """

    def __init__(
        self,
        fps: float,
        end_s: float,
        desc: str = "",
        enabled: bool = True,
        file: TextIO | None = None,
    ) -> None:
        from tqdm import tqdm

        self.fps = float(fps)
        self.bar: Any = tqdm(
            total=self.frames_until(end_s),
            unit=" frame",
            desc=desc,
            disable=not enabled,
            leave=False,
            dynamic_ncols=True,
            file=file,
        )

    def frames_until(self, t_s: float) -> int:
        """Frames of a video that ends at ``t_s`` (frame k shows time k / fps)."""
        if not math.isfinite(t_s) or t_s < 0:
            return 1
        return int(math.floor(t_s * self.fps + 1e-9)) + 1

    @property
    def n(self) -> int:
        return int(self.bar.n)

    @property
    def total(self) -> int:
        return int(self.bar.total)

    def advance(self, end_s: float | None = None) -> None:
        """One more frame written; ``end_s``: the video's end once known (s; ``None``: keep
        the estimate, raised only as far as the count needs)."""
        total = self.frames_until(end_s) if end_s is not None else int(self.bar.total)
        total = max(self.n + 1, total)
        if total != self.bar.total:
            self.bar.total = total
        self.bar.update(1)

    def finish(self) -> None:
        """The video ended: the total is what was written."""
        if self.bar.total != self.bar.n:
            self.bar.total = self.bar.n
            self.bar.refresh()

    def __enter__(self) -> FrameProgress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.bar.close()
