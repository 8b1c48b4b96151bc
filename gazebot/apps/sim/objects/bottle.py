"""Plastic and glass bottles (seed Fig. 6.7b): same shape, different look."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco

from gazebot.apps.sim.objects.base import HandoverObject, visual_geom


@dataclass
class Bottle(HandoverObject):
    """An upright bottle: a cylindrical body, a shoulder and a neck with a cap."""

    radius: float = 0.035
    body_half_height: float = 0.085
    rgba: tuple[float, float, float, float] = (0.45, 0.7, 0.95, 0.75)
    cap_rgba: tuple[float, float, float, float] = (0.1, 0.3, 0.8, 1.0)

    @property
    def half_extent_x(self) -> float:
        return self.radius

    @property
    def half_height(self) -> float:
        return self.body_half_height + 0.05

    def add_geoms(self, body: mujoco.MjsBody) -> None:
        r, h = self.radius, self.body_half_height
        cyl, sph = mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_SPHERE
        visual_geom(body, type=cyl, size=[r, h, 0], pos=[0, 0, -0.02], rgba=self.rgba)
        visual_geom(body, type=sph, size=[r, 0, 0], pos=[0, 0, h - 0.02], rgba=self.rgba)
        visual_geom(body, type=cyl, size=[r * 0.42, 0.03, 0], pos=[0, 0, h + 0.03], rgba=self.rgba)
        visual_geom(
            body, type=cyl, size=[r * 0.48, 0.01, 0], pos=[0, 0, h + 0.065], rgba=self.cap_rgba
        )


def plastic_bottle() -> Bottle:
    return Bottle()


def glass_bottle() -> Bottle:
    # Green glass, darker and more opaque than PET, with a metal cap.
    return Bottle(rgba=(0.2, 0.55, 0.3, 0.85), cap_rgba=(0.75, 0.75, 0.7, 1.0))
