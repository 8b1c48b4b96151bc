"""Reach-phase gaze patterns (seed section 6.3.1, figure 6.1).

- ``Hand``: the other person's hand throughout the reach.
- ``Face``: the other person's face throughout the reach.
- ``Short Face-Hand``: face, then hand; the face lasts at most half of the reach.
- ``Long Face-Hand``: face, then hand; the face lasts more than half of the reach.
- ``other``: anything else (e.g. hand then face, or no reach frames).

The reach is the frames the person's own phase column labels ``Reach``. Durations are counted in
frames from the start of the reach, ignored frames (see :mod:`~gazebot.annotations.rules`)
included: the face gaze lasts until the first hand frame.
"""

from __future__ import annotations

from gazebot.annotations.loader import AnnotatedHandover
from gazebot.annotations.rules import DEFAULT_RULE, GazeRule

REACH_PATTERNS = ("Hand", "Face", "Short Face-Hand", "Long Face-Hand", "other")


def classify_reach(gaze: list[str | None]) -> str:
    """Pattern of one reach given its per-frame targets (``face``/``hand``/None = ignored)."""
    n = len(gaze)
    seen = [g for g in gaze if g is not None]
    if n == 0 or not seen:
        return "other"
    runs = [g for i, g in enumerate(seen) if i == 0 or g != seen[i - 1]]
    if runs == ["hand"]:
        return "Hand"
    if runs == ["face"]:
        return "Face"
    if runs == ["face", "hand"]:
        first_hand = gaze.index("hand")  # frames of face gaze before it (ignored ones included)
        return "Short Face-Hand" if first_hand <= n / 2 else "Long Face-Hand"
    return "other"


def reach_pattern(handover: AnnotatedHandover, role: str, rule: GazeRule = DEFAULT_RULE) -> str:
    """Reach-phase gaze pattern of ``role`` (``giver`` or ``receiver``) in ``handover``."""
    gaze = [
        rule.target(g)
        for g, p in zip(handover.gaze(role), handover.phase(role), strict=True)
        if p == "reach"
    ]
    return classify_reach(gaze)
