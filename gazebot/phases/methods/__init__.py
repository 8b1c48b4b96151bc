"""Phase methods, one per file, each a :class:`Segmenter` (offline: whole recording in,
segments out). The online :class:`~gazebot.phases.detector.PhaseDetector` runs any of them on the
samples seen so far.

- ``gazebot`` (:class:`GazebotSegmenter`): the robust default;
- ``seed-7.2.5`` (:class:`Seed725Segmenter`): the seed's annotation rule as published;
- ``seed-4.4.3`` (:class:`Seed443Segmenter`): the seed's split of giving motions.
"""

from __future__ import annotations

from gazebot.phases.config import PhaseConfig
from gazebot.phases.methods.base import Segmenter
from gazebot.phases.methods.gazebot import GazebotSegmenter
from gazebot.phases.methods.seed_443 import Seed443Segmenter
from gazebot.phases.methods.seed_725 import Seed725Segmenter

SEGMENTERS: dict[str, type[Segmenter]] = {
    "gazebot": GazebotSegmenter,
    "seed-7.2.5": Seed725Segmenter,
    "seed-4.4.3": Seed443Segmenter,
}


def make_segmenter(config: PhaseConfig) -> Segmenter:
    """The segmenter of ``config.method``."""
    return SEGMENTERS[config.method](config)


__all__ = [
    "SEGMENTERS",
    "GazebotSegmenter",
    "Seed443Segmenter",
    "Seed725Segmenter",
    "Segmenter",
    "make_segmenter",
]
