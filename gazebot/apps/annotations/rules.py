"""How annotated gaze labels count: which labels are face, which hand, which are ignored.

The published labels are the other person's face, the other person's hand, ``Own Hand`` and
``Other``. The seed's patterns only speak of face and hand, so the two remaining labels need a rule.
The default (:data:`DEFAULT_RULE`):

- ``Own Hand`` counts as **hand**. It is task-oriented gaze at the object being handed over: the
  seed already folds gaze at the handover location into "hand" (section 6.2), and during transfer
  and retreat the object sits in the receiver's own hand (1377 of the receivers' frames are
  ``Own Hand``, nearly all in transfer and retreat).
- ``Other`` is **ignored**: the frame neither counts as face nor as hand and does not break a
  pattern (a glance elsewhere or a blink), but it still takes time: phase lengths and the
  "half of the reach" criterion count every frame.

This choice reproduces the seed's published Hand shares of 6.4.2 for receivers (17.4 %) and
the order of all six three-phase shares; ``gazebot annotations summarize`` prints the comparison.
"""

from __future__ import annotations

from dataclasses import dataclass

_CHOICES = ("face", "hand", "ignore")


@dataclass(frozen=True)
class GazeRule:
    """How the labels ``own_hand`` and ``other`` count (``face``, ``hand`` or ``ignore``)."""

    own_hand: str = "hand"
    other: str = "ignore"

    def __post_init__(self) -> None:
        for name in ("own_hand", "other"):
            if getattr(self, name) not in _CHOICES:
                raise ValueError(f"GazeRule.{name} must be one of {_CHOICES}")

    def target(self, label: str) -> str | None:
        """``face``, ``hand`` or None (ignored) for a normalised gaze label."""
        if label == "face" or label == "hand":
            return label
        choice = self.own_hand if label == "own_hand" else self.other
        return None if choice == "ignore" else choice


DEFAULT_RULE = GazeRule()
