"""The seed's study designs (sections 6.3 and 6.4, Tables 6.3/6.4): behaviors, conditions, their
levels, the scenes that show them and the robot's gaze mode in each study.

A module without heavy imports, so the command line can list the conditions in ``--help``.
"""

from __future__ import annotations

# Section 6.4 (Table 6.4): the three behaviors as the Sawyer showed them, keyed on its sensors and
# its own motion (6.4.3: "the robot was programmed to use the sensor information to initiate the
# handovers and gaze behaviors depending on the phase of the handover").
DEFAULT_BEHAVIORS = ("hand-face-as-studied", "face-hand-face-as-studied", "hand")
# Section 6.3.2: "We programmed the head of the robot to exhibit the following four gaze
# behaviors", compared with no condition ("The 12 sessions consisted of the six possible pairings
# of the four gaze patterns and their reverse order").
REACH_BEHAVIORS = ("face", "hand", "short-face-hand", "long-face-hand")

# Table 6.3: the two levels (a, b) of each condition.
CONDITION_LEVELS: dict[str, tuple[str, str]] = {
    "object-size": ("small-box", "large-box"),
    "fragility": ("plastic-bottle", "glass-bottle"),
    "posture": ("sitting", "standing"),
}
# The shipped scene (configs/scenes/<name>.yaml) that shows each level; "" is the single scenario
# of a study without a condition (6.3: the robot starts its reach, the giver responds).
DEFAULT_SCENES: dict[str, str] = {
    "": "robot-initiated",
    "small-box": "small-object",
    "large-box": "large-object",
    "plastic-bottle": "non-fragile",
    "glass-bottle": "fragile",
    "sitting": "sitting",
    "standing": "standing",
}

# How the robot shows its gaze (robot config / ``--gaze-mode``).
GAZE_MODES = ("head-and-eyes", "head-only", "eyes-only")
# 6.3.2: a head with "a 7-inch screen that displayed a static image of two eyes";
# 6.4: "We use robot eye gazes instead of head gazes".
DEFAULT_GAZE_MODE_NO_CONDITION = "head-only"
DEFAULT_GAZE_MODE_WITH_CONDITION = "eyes-only"


# 6.3.2: "a Kinova Jaco-2 robot arm, accompanied by a simple robot head"; 6.4.3: "implemented
# on a Sawyer cobot". Both ship as robot configs (configs/robots/<name>.yaml).
DEFAULT_ROBOT_NO_CONDITION = "jaco2"
DEFAULT_ROBOT_WITH_CONDITION = "sawyer"


def default_robot(condition: str | None) -> str:
    """The robot the seed's design ran on: the Jaco-2 with its head in 6.3, the Sawyer in 6.4."""
    return DEFAULT_ROBOT_WITH_CONDITION if condition else DEFAULT_ROBOT_NO_CONDITION


def default_behaviors(condition: str | None) -> tuple[str, ...]:
    """The seed's behaviors for a design: 6.3's four without a condition, 6.4's three with one."""
    return DEFAULT_BEHAVIORS if condition else REACH_BEHAVIORS


def default_gaze_mode(condition: str | None) -> str:
    """The gaze mode the seed's robot used in the design (head-only in 6.3, eyes-only in 6.4)."""
    return DEFAULT_GAZE_MODE_WITH_CONDITION if condition else DEFAULT_GAZE_MODE_NO_CONDITION
