"""The handed-over object: a kinematic (mocap) body whose geoms each kind adds."""

from __future__ import annotations

from abc import ABC, abstractmethod

import mujoco


class HandoverObject(ABC):
    """Base class of the objects of seed Fig. 6.7 (boxes, bottles).

    The object is kinematic: the simulation places it in the giver's hand or the robot's gripper,
    so a handover never depends on friction tuning.
    """

    name: str = "handover_object"

    @property
    @abstractmethod
    def half_extent_x(self) -> float:
        """Half the object's depth along the line between giver and robot (m)."""

    @property
    @abstractmethod
    def half_height(self) -> float:
        """Half the object's height (m)."""

    @abstractmethod
    def add_geoms(self, body: mujoco.MjsBody) -> None:
        """Add visual geoms centered on ``body``'s origin (no collisions)."""

    def add_to(self, spec: mujoco.MjSpec) -> mujoco.MjsBody:
        body = spec.worldbody.add_body(name=self.name, mocap=True)
        self.add_geoms(body)
        return body


def visual_geom(body: mujoco.MjsBody, **kwargs) -> mujoco.MjsGeom:
    """A geom that is seen but never collides (the scene around the robot is kinematic)."""
    return body.add_geom(contype=0, conaffinity=0, group=1, **kwargs)
