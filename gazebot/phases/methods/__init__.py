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
from gazebot.registry import Registry

#: The phase methods by name: ``method:`` validation, CLI choices and the README's table come
#: from here. A new method is one file plus one line.
PHASE_METHODS: Registry[Segmenter] = Registry("phase method", group="gazebot.phase_methods")
PHASE_METHODS.register("gazebot", GazebotSegmenter, "the robust default")
PHASE_METHODS.register(
    "seed-7.2.5", Seed725Segmenter, "the seed's annotation rule as published (section 7.2.5)"
)
PHASE_METHODS.register(
    "seed-4.4.3", Seed443Segmenter, "the seed's split of giving motions (section 4.4.3)"
)
#: The built-in methods' classes by name (kept for code written before the registry).
SEGMENTERS: dict[str, type[Segmenter]] = {
    "gazebot": GazebotSegmenter,
    "seed-7.2.5": Seed725Segmenter,
    "seed-4.4.3": Seed443Segmenter,
}


def make_segmenter(config: PhaseConfig) -> Segmenter:
    """The segmenter of ``config.method`` (a registered phase method)."""
    return PHASE_METHODS.make(config.method, config)


__all__ = [
    "PHASE_METHODS",
    "SEGMENTERS",
    "GazebotSegmenter",
    "Seed443Segmenter",
    "Seed725Segmenter",
    "Segmenter",
    "make_segmenter",
]
