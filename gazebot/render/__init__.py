"""Off-screen eye images for the robots' head screens, and the blink model that drives them.

``EyeRenderer.for_robot("sawyer").render(eye_yaw, eye_pitch, blink, distance)`` returns an RGB
image; ``BlinkModel(seed).update(t, gaze_shift_rad)`` returns the blink (0 open .. 1 closed).
The eye state travels on the bus as :class:`gazebot.drivers.payloads.EyeStateMsg` (tens of
bytes); ``gazebot display`` draws it on the robot's head screen with the same renderer.

``gazebot.render.video`` (the H.264 MP4 writer) and ``gazebot.render.timeline`` (the timeline CSV
and plot) are imported on their own; the handover recording loop that drives the simulation is
``gazebot.sim.record`` (render draws things, it does not run them).
"""

from __future__ import annotations

from gazebot.render.blink import BlinkConfig, BlinkModel
from gazebot.render.eye_style import EyeStyle, available_eye_styles, load_eye_style
from gazebot.render.eyes import EyeRenderer
from gazebot.render.eyes_display import RobotDisplay, robot_display

__all__ = [
    "BlinkConfig",
    "BlinkModel",
    "EyeRenderer",
    "EyeStyle",
    "RobotDisplay",
    "available_eye_styles",
    "load_eye_style",
    "robot_display",
]
