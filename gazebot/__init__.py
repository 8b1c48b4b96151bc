"""gazebot: robot gaze behaviors for human-to-robot object handovers.

Entry points: :class:`GazeEngine` (embed in a robot stack), the ``gazebot`` command line, and the
layers :mod:`gazebot.core` (the engine), :mod:`gazebot.io` (the bus, recordings) and
:mod:`gazebot.apps` (simulator, renderers, study, command line). ``pip install gazebot`` installs
what the core and io need; the apps' extras (``gazebot[sim]``, ``[render]``, ``[study]``, ...) the
rest, and a command whose extra is missing says which.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gazebot.core.types import (
    Event,
    EventKind,
    GazeCommand,
    GazeContext,
    GazeTarget,
    Phase,
    TrackingFrame,
)

if TYPE_CHECKING:
    from gazebot.core.engine import GazeEngine

__all__ = [
    "Event",
    "EventKind",
    "GazeCommand",
    "GazeContext",
    "GazeEngine",
    "GazeTarget",
    "Phase",
    "TrackingFrame",
]
__version__ = "0.1.0"


def __getattr__(name: str):
    # The engine pulls in Pinocchio; import it only when asked for.
    if name == "GazeEngine":
        from gazebot.core.engine import GazeEngine

        return GazeEngine
    raise AttributeError(f"module 'gazebot' has no attribute {name!r}")
