"""Video-study toolkit (seed chapter 6): counterbalanced plans, rendering of the study videos,
and the Bradley-Terry preference analysis with the seed's significance tests.

The names below are imported on first use (PEP 562), so that ``gazebot --help`` can read the
study's conditions (:mod:`gazebot.apps.study.conditions`) without loading SciPy.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS: dict[str, str] = {
    "CONDITION_LEVELS": "conditions",
    "DEFAULT_BEHAVIORS": "conditions",
    "MEASURES": "questionnaire",
    "QUESTIONS": "questionnaire",
    "RESPONSE_COLUMNS": "analysis",
    "BradleyTerryFit": "bradley_terry",
    "Response": "analysis",
    "Session": "plan",
    "StudyAnalysis": "analysis",
    "analyze": "analysis",
    "bradley_terry_chi2": "stats",
    "check_balance": "plan",
    "fit_bradley_terry": "bradley_terry",
    "likelihood_ratio_chi2": "stats",
    "make_plan": "plan",
    "matched_equivalence": "stats",
    "matched_proportion_difference": "stats",
    "ordered_pairings": "plan",
    "position_bias_test": "stats",
    "read_plan": "plan",
    "read_responses": "analysis",
    "read_win_matrix": "analysis",
    "unmatched_equivalence": "stats",
    "unmatched_proportion_difference": "stats",
    "williams_square": "plan",
    "win_matrix": "analysis",
    "write_plan": "plan",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name not in _EXPORTS:
        raise AttributeError(f"module 'gazebot.apps.study' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"gazebot.apps.study.{_EXPORTS[name]}"), name)
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_EXPORTS])
