"""Reach-phase gaze patterns (seed section 6.3.1, figure 6.1).

- ``Hand``: the other person's hand throughout the reach.
- ``Face``: the other person's face throughout the reach.
- ``Short Face-Hand``: face, then hand; the face lasts at most half of the reach.
- ``Long Face-Hand``: face, then hand; the face lasts more than half of the reach.
- ``other``: anything else (e.g. hand then face, or no reach frames).

The reach is the frames the person's own phase column labels ``Reach``. Durations are counted in
frames from the start of the reach, ignored frames (see :mod:`~gazebot.apps.annotations.rules`)
included: the face gaze lasts until the first hand frame.

Why this window. Our mean reach lengths (giver 7.89, receiver 6.43 frames) differ from the seed's
figure 6.1 (8.10, 7.53), so other windows were tried on the 288 handovers. Both people's reaches
end where the shared transfer starts, the receiver starts reaching 1.46 frames after the giver on
average (the seed's means imply 0.57), and no ``Approach``/``Other`` frame falls inside a reach.
So any window "own reach + k frames" keeps the 1.46-frame gap and no window matches both published
means. Mean lengths giver/receiver and Hand shares giver/receiver (seed 35.8/69.1 %):

- own reach (this rule): 7.89/6.43, Hand 42.0/80.2 %;
- the union of both reaches: 8.04/8.04, Hand 39.6/60.8 % (receiver Short F-H 33.0 vs 21.5);
- the other person's reach: 6.43/7.89, Hand 56.2/61.5 %;
- own reach plus the first transfer frame: 8.86/7.41, Hand 41.3/79.9 %;
- own reach plus the frame before it: 8.89/7.43, Hand 30.6/62.8 %;
- own reach plus ``Approach``: 15.41/14.47, Long F-H 39.2/35.1 %.

None brings the eight published shares closer (sum of absolute gaps: own 45.2 points, union
45.9, the rest worse). Sweeping the window's start and end by whole frames, the windows closest
to the shares end two frames before the transfer (about 5 frames long), contradicting the
published lengths. The seed's figures may come from a labelling that differs from the public
files; lacking a window that reproduces them, the plain own-reach window stays
(``tests/apps/annotations/test_annotations_real_data.py`` states each published figure beside
ours, with the gap and its measured reason).
"""

from __future__ import annotations

from gazebot.apps.annotations.loader import AnnotatedHandover
from gazebot.apps.annotations.rules import DEFAULT_RULE, GazeRule

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
