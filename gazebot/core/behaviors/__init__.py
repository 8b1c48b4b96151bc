"""Gaze behaviors: what the robot looks at in each handover phase.

- :mod:`~gazebot.core.behaviors.segment`: a gaze segment ``{phase, at, target}`` and its ``at``
forms.
- :mod:`~gazebot.core.behaviors.spec`: the YAML format (:class:`BehaviorSpec`).
- :mod:`~gazebot.core.behaviors.machine`: :class:`BehaviorMachine`, the ``transitions`` state
machine whose states are the gaze decisions (phase events and timers in, gaze target out), and
  :func:`~gazebot.core.behaviors.machine.diagram` (its Mermaid drawing).
- :mod:`~gazebot.core.behaviors.registry`: :func:`load_behavior` and :func:`list_behaviors`
(built-ins in
  ``configs/behaviors/`` plus user folders), :func:`seed_behaviors` (the built-ins implementing
  the seed's gaze behaviors).
- :mod:`~gazebot.core.behaviors.human`: the data-driven ``human-receiver`` timing model (read from
  YAML; fitted by :mod:`gazebot.apps.annotations.fit`, so this package never imports annotations).
"""

from gazebot.core.behaviors.machine import BehaviorMachine, GazeOrigin
from gazebot.core.behaviors.registry import (
    BehaviorInfo,
    behavior_errors,
    behavior_path,
    known_targets,
    list_behaviors,
    load_behavior,
    seed_behaviors,
)
from gazebot.core.behaviors.spec import AtEvent, AtFraction, AtNever, BehaviorSpec, Segment

__all__ = [
    "AtEvent",
    "AtFraction",
    "AtNever",
    "BehaviorInfo",
    "BehaviorMachine",
    "GazeOrigin",
    "BehaviorSpec",
    "Segment",
    "behavior_errors",
    "behavior_path",
    "known_targets",
    "list_behaviors",
    "load_behavior",
    "seed_behaviors",
]
