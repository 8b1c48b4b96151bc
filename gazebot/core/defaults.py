"""Defaults that several layers share, each stated once here: the engine, the runtime loop, the
simulator, the renderers and the command line take their default robot and behavior from here."""

from __future__ import annotations

#: The robot used when none is given: a name of ``configs/robots/<name>.yaml``.
DEFAULT_ROBOT = "sawyer"

#: The gaze behavior used when none is given: a name of ``configs/behaviors/<name>.yaml``.
DEFAULT_BEHAVIOR = "face-hand-face"
