"""The seed's study design constants (Tables 6.3/6.4): behaviors, conditions and their levels.

A module without heavy imports, so the command line can list the conditions in ``--help``.
"""

from __future__ import annotations

DEFAULT_BEHAVIORS = ("hand-face", "face-hand-face", "hand")

# Table 6.3: the two levels (a, b) of each condition.
CONDITION_LEVELS: dict[str, tuple[str, str]] = {
    "object-size": ("small-box", "large-box"),
    "fragility": ("plastic-bottle", "glass-bottle"),
    "posture": ("sitting", "standing"),
}
# The shipped scene (configs/scenes/<name>.yaml) that shows each level.
DEFAULT_SCENES: dict[str, str] = {
    "small-box": "small-object",
    "large-box": "large-object",
    "plastic-bottle": "non-fragile",
    "glass-bottle": "fragile",
    "sitting": "sitting",
    "standing": "standing",
}
