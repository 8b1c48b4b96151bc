"""Video-study toolkit (seed chapter 6): counterbalanced plans, rendering of the study videos,
and the Bradley-Terry preference analysis with the seed's significance tests."""

from gazebot.study.analysis import (
    RESPONSE_COLUMNS,
    Response,
    StudyAnalysis,
    analyze,
    read_responses,
    read_win_matrix,
    win_matrix,
)
from gazebot.study.bradley_terry import BradleyTerryFit, fit_bradley_terry
from gazebot.study.plan import (
    CONDITION_LEVELS,
    DEFAULT_BEHAVIORS,
    Session,
    check_balance,
    make_plan,
    ordered_pairings,
    read_plan,
    williams_square,
    write_plan,
)
from gazebot.study.questionnaire import MEASURES, QUESTIONS
from gazebot.study.stats import (
    bradley_terry_chi2,
    likelihood_ratio_chi2,
    matched_equivalence,
    matched_proportion_difference,
    position_bias_test,
    unmatched_equivalence,
    unmatched_proportion_difference,
)

__all__ = [
    "CONDITION_LEVELS",
    "DEFAULT_BEHAVIORS",
    "MEASURES",
    "QUESTIONS",
    "RESPONSE_COLUMNS",
    "BradleyTerryFit",
    "Response",
    "Session",
    "StudyAnalysis",
    "analyze",
    "bradley_terry_chi2",
    "check_balance",
    "fit_bradley_terry",
    "likelihood_ratio_chi2",
    "make_plan",
    "matched_equivalence",
    "matched_proportion_difference",
    "ordered_pairings",
    "position_bias_test",
    "read_plan",
    "read_responses",
    "read_win_matrix",
    "unmatched_equivalence",
    "unmatched_proportion_difference",
    "williams_square",
    "win_matrix",
    "write_plan",
]
