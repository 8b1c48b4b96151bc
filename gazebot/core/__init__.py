"""gazebot's core: the values (:mod:`~gazebot.core.types`), phases, the handover state, behaviors,
kinematics, the engine and the runtime loop.

The core imports nothing of :mod:`gazebot.io` or :mod:`gazebot.apps` (``make lint`` checks it):
a robot stack that embeds :class:`~gazebot.core.engine.GazeEngine` needs only this layer.
"""
