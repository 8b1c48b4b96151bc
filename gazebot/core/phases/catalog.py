"""The phase methods by name: ``method:`` validation, CLI choices and the README's table come
from here. A new method is one file in :mod:`gazebot.core.phases.methods` plus one line; each is
imported on first use, so the configuration can check a name without importing the methods."""

from __future__ import annotations

from typing import TYPE_CHECKING

from gazebot.core.registry import Registry

if TYPE_CHECKING:
    from gazebot.core.phases.methods.base import Segmenter

_METHODS = "gazebot.core.phases.methods"

PHASE_METHODS: Registry[Segmenter] = Registry("phase method", group="gazebot.phase_methods")
PHASE_METHODS.register("gazebot", f"{_METHODS}.gazebot:GazebotSegmenter", "the robust default")
PHASE_METHODS.register(
    "seed-7.2.5", f"{_METHODS}.seed_725:Seed725Segmenter",
    "the seed's annotation rule as published (section 7.2.5)",
)
PHASE_METHODS.register(
    "seed-4.4.3", f"{_METHODS}.seed_443:Seed443Segmenter",
    "the seed's split of giving motions (section 4.4.3)",
)
