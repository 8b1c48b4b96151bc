"""Simulated human-to-robot handovers in MuJoCo: scene composition, the simulated giver, the robot's
handover controller and off-screen rendering.

Import :class:`HandoverSimulation` from here; everything heavy (MuJoCo) loads on first use.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from gazebot.apps.sim.scene_config import SceneConfig, load_scene, scene_names
    from gazebot.apps.sim.simulation import HandoverSimulation

__all__ = ["HandoverSimulation", "SceneConfig", "load_scene", "scene_names"]


def __getattr__(name: str):
    if name == "HandoverSimulation":
        from gazebot.apps.render.gl_check import ensure_gl_backend

        # Pick an off-screen GL back end before MuJoCo loads (EGL unless MUJOCO_GL says).
        ensure_gl_backend(probe_first=False)
        from gazebot.apps.sim.simulation import HandoverSimulation

        return HandoverSimulation
    if name in ("SceneConfig", "load_scene", "scene_names"):
        from gazebot.apps.sim import scene_config

        return getattr(scene_config, name)
    raise AttributeError(f"module 'gazebot.apps.sim' has no attribute {name!r}")
