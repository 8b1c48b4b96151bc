"""Phase methods, one per file, each a :class:`Segmenter` (offline: whole recording in,
segments out). The online :class:`~gazebot.core.phases.detector.PhaseDetector` runs any of them on
the samples seen so far.

- ``gazebot`` (:class:`GazebotSegmenter`): the robust default;
- ``seed-7.2.5`` (:class:`Seed725Segmenter`): the seed's annotation rule as published;
- ``seed-4.4.3`` (:class:`Seed443Segmenter`): the seed's split of giving motions.
"""

from __future__ import annotations

from gazebot.core.phases.catalog import PHASE_METHODS
from gazebot.core.phases.config import PhaseConfig
from gazebot.core.phases.methods.base import Segmenter
from gazebot.core.phases.methods.gazebot import GazebotSegmenter
from gazebot.core.phases.methods.seed_443 import Seed443Segmenter
from gazebot.core.phases.methods.seed_725 import Seed725Segmenter


def make_segmenter(config: PhaseConfig) -> Segmenter:
    """The segmenter of ``config.method`` (a registered phase method)."""
    return PHASE_METHODS.make(config.method, config)


__all__ = [
    "PHASE_METHODS",
    "GazebotSegmenter",
    "Seed443Segmenter",
    "Seed725Segmenter",
    "Segmenter",
    "make_segmenter",
]
