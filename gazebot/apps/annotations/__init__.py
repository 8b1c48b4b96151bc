"""The human-human handover gaze annotations (seed section 6.2): loading, patterns, replay.

- :mod:`~gazebot.apps.annotations.loader`: read the published xlsx layout, reporting oddities.
- :mod:`~gazebot.apps.annotations.rules`: how ``Own Hand`` and ``Other`` frames count.
- :mod:`~gazebot.apps.annotations.reach` / :mod:`~gazebot.apps.annotations.three_phase`: the seed's
  reach-phase (6.3.1) and three-phase (6.4.2) gaze patterns.
- :mod:`~gazebot.apps.annotations.summary`: pattern shares beside the seed's published ones.
- :mod:`~gazebot.apps.annotations.replay`: run behaviors along the annotated phases and score them.
- :mod:`~gazebot.apps.annotations.fit`: fit the data-driven ``human-<role>`` behavior.
"""

from gazebot.apps.annotations.fit import fit_human_model
from gazebot.apps.annotations.loader import (
    AnnotatedHandover,
    AnnotationSet,
    LoadIssue,
    load_annotations,
    load_handover,
)
from gazebot.apps.annotations.reach import REACH_PATTERNS, classify_reach, reach_pattern
from gazebot.apps.annotations.replay import ReplayResult, replay, replay_handover
from gazebot.apps.annotations.rules import DEFAULT_RULE, GazeRule
from gazebot.apps.annotations.summary import Summary, plot_summary, summarize
from gazebot.apps.annotations.three_phase import (
    THREE_PHASE_PATTERNS,
    classify_three_phase,
    three_phase_pattern,
)

__all__ = [
    "DEFAULT_RULE",
    "REACH_PATTERNS",
    "THREE_PHASE_PATTERNS",
    "AnnotatedHandover",
    "AnnotationSet",
    "GazeRule",
    "LoadIssue",
    "ReplayResult",
    "Summary",
    "classify_reach",
    "fit_human_model",
    "classify_three_phase",
    "load_annotations",
    "load_handover",
    "plot_summary",
    "reach_pattern",
    "replay",
    "replay_handover",
    "summarize",
    "three_phase_pattern",
]
