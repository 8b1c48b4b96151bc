"""Off-screen eye images for the robots' head screens.

``EyeRenderer.for_robot(DEFAULT_ROBOT).render(eye_yaw, eye_pitch, blink, distance)`` returns an RGB
image. The blink that closes the lids comes from the runtime loop's
:class:`~gazebot.core.runtime.blink.BlinkModel`.
The eye state travels on the bus as ``gazebot_msgs/EyeState`` (tens of bytes;
:class:`gazebot.io.ros2.values.EyeState`); ``gazebot display`` draws it on the robot's head
screen with the same renderer.

``gazebot.apps.render.video`` (the H.264 MP4 writer) and ``gazebot.apps.render.timeline`` (the
timeline CSV
and plot) are imported on their own; the handover recording loop that drives the simulation is
``gazebot.apps.sim.record`` (render draws things, it does not run them).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from gazebot.apps.render.eye_style import EyeStyle, available_eye_styles, load_eye_style
    from gazebot.apps.render.eyes import EyeRenderer, LazyEyeRenderer
    from gazebot.apps.render.eyes_display import RobotDisplay, robot_display

__all__ = [
    "EyeRenderer",
    "LazyEyeRenderer",
    "EyeStyle",
    "RobotDisplay",
    "available_eye_styles",
    "load_eye_style",
    "robot_display",
]

# Where each name lives: the eye renderer needs OpenCV (the ``render`` extra); the styles and
# display sizes do not, so the CLI lists eye styles on the core install.
_HOMES = {
    "EyeRenderer": "eyes",
    "LazyEyeRenderer": "eyes",
    "EyeStyle": "eye_style",
    "available_eye_styles": "eye_style",
    "load_eye_style": "eye_style",
    "RobotDisplay": "eyes_display",
    "robot_display": "eyes_display",
}


def __getattr__(name: str):
    if name in _HOMES:
        import importlib

        return getattr(importlib.import_module(f"gazebot.apps.render.{_HOMES[name]}"), name)
    raise AttributeError(f"module 'gazebot.apps.render' has no attribute {name!r}")
