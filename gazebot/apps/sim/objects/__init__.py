"""Objects the giver hands over (seed Fig. 6.7): a base class and one module per kind."""

from __future__ import annotations

from gazebot.apps.sim.objects.base import HandoverObject
from gazebot.apps.sim.objects.bottle import Bottle, glass_bottle, plastic_bottle
from gazebot.apps.sim.objects.box import Box, large_box, small_box
from gazebot.apps.sim.scene_config import ObjectKind

_FACTORIES = {
    ObjectKind.SMALL_BOX: small_box,
    ObjectKind.LARGE_BOX: large_box,
    ObjectKind.PLASTIC_BOTTLE: plastic_bottle,
    ObjectKind.GLASS_BOTTLE: glass_bottle,
}


def make_object(kind: ObjectKind | str) -> HandoverObject:
    """The object of ``kind`` (one of :class:`ObjectKind`, e.g. ``small_box``)."""
    try:
        return _FACTORIES[ObjectKind(kind)]()
    except ValueError as exc:
        known = ", ".join(k.value for k in ObjectKind)
        raise ValueError(f"unknown object kind {kind!r} (known: {known})") from exc


__all__ = ["Bottle", "Box", "HandoverObject", "make_object"]
