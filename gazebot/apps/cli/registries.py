"""Every extension kind's registry in one place: what the CLI offers and the README lists."""

from __future__ import annotations

from gazebot.core.registry import FolderRegistry, NameRegistry


def registries() -> dict[str, NameRegistry]:
    """Every extension kind's registry: robots, behaviors, phase methods, controllers, eye
    styles and scenes."""
    from gazebot.apps.controllers import CONTROLLERS
    from gazebot.apps.render.eye_style import available_eye_styles
    from gazebot.apps.sim.scene_config import scene_names
    from gazebot.core.behaviors import list_behaviors
    from gazebot.core.config import configs_dir
    from gazebot.core.phases.methods import PHASE_METHODS

    def robots() -> list[str]:
        return sorted(p.stem for p in (configs_dir() / "robots").glob("*.yaml"))

    return {
        "robots": FolderRegistry("robot", robots),
        "behaviors": FolderRegistry("behavior", lambda: [b.name for b in list_behaviors()]),
        "phase methods": PHASE_METHODS,
        "controllers": CONTROLLERS,
        "eye styles": FolderRegistry("eye style", available_eye_styles),
        "scenes": FolderRegistry("scene", scene_names),
    }
