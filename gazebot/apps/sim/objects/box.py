"""Small and large cardboard boxes (seed Fig. 6.7a)."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco

from gazebot.apps.sim.objects.base import HandoverObject, visual_geom


@dataclass
class Box(HandoverObject):
    """A box of half sizes ``(x, y, z)`` in m; x points from the giver to the robot."""

    half_size: tuple[float, float, float] = (0.04, 0.06, 0.05)
    rgba: tuple[float, float, float, float] = (0.78, 0.6, 0.38, 1.0)

    @property
    def half_extent_x(self) -> float:
        return self.half_size[0]

    @property
    def half_height(self) -> float:
        return self.half_size[2]

    def add_geoms(self, body: mujoco.MjsBody) -> None:
        visual_geom(body, type=mujoco.mjtGeom.mjGEOM_BOX, size=list(self.half_size), rgba=self.rgba)
        # A tape strip so the box reads as a parcel in the video.
        hx, hy, hz = self.half_size
        visual_geom(
            body,
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[hx + 0.001, min(0.015, hy / 4), hz + 0.001],
            rgba=(0.55, 0.42, 0.26, 1.0),
        )


def small_box() -> Box:
    return Box(half_size=(0.04, 0.055, 0.045))


def large_box() -> Box:
    return Box(half_size=(0.11, 0.16, 0.12))
