"""The summary, replay and the shipped human model on the real 288 annotated handovers."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import pytest

from gazebot.apps.annotations import load_annotations, replay, summarize
from gazebot.apps.annotations.fit import fit_human_model
from gazebot.apps.annotations.reach import classify_reach
from gazebot.apps.annotations.rules import DEFAULT_RULE
from gazebot.apps.annotations.summary import SEED_REACH, SEED_REACH_FRAMES, SEED_THREE_PHASE
from gazebot.core.behaviors import load_behavior


@pytest.fixture(scope="module")
def annotations(annotations_dir):
    return load_annotations(annotations_dir)


@pytest.fixture(scope="module")
def summary(annotations):
    return summarize(annotations)


def test_all_288_handovers_load_and_oddities_are_reported(annotations):
    assert len(annotations) == 288
    assert sum(h.n_frames for h in annotations.handovers) == 14214  # seed 6.2: 14214 frames
    messages = {i.message for i in annotations.issues}
    assert "stray cells ignored" in messages  # a ' ' right of the table in one file


def test_summary_shares_are_percent_of_all_handovers(summary):
    doc = summary.to_json()
    assert doc["n_handovers"] == 288
    for group in ("reach", "three_phase"):
        for role in ("giver", "receiver"):
            assert sum(doc[group][role].values()) == pytest.approx(100.0, abs=0.3)


# ------------------------------------------------------------------ the published figures
# One test per number the seed publishes in Fig. 6.1 (reach, section 6.3.1) and Fig. 6.5 /
# section 6.4.2 (three phases): each states our measured value beside the seed's, the gap and
# why. Our rule (gazebot.apps.annotations.reach: each person's own ``Reach`` frames, ``Own Hand`` as
# hand, ``Other`` ignored) is ours; the seed's window is not given, and no window tried on the
# public files reproduces its figures (see gazebot.apps.annotations.reach for the sweep).
LATE_RECEIVER = (
    "the public files' receiver reach starts 1.46 frames after the giver's (the seed's mean "
    "lengths imply 0.57), so receivers' face glances before their own reach fall outside it"
)
GIVER_TURN_LATE = (
    "some givers turn from face to hand only in their reach's last frames: without the last two "
    "frames 10 of our Short Face-Hand givers are Face (27); the other 8 of the gap no window "
    "tried explains"
)
GIVER_HAND = (
    "no window tried explains it: 114 with the frames where either person reaches, 123 without "
    "the own reach's last two frames; the seed's labelling may differ from the public files"
)
# The seed's four giver counts sum to 251 of 288 (37 handovers in no published pattern); ours
# leave 6 in ``other``.


@dataclass(frozen=True)
class Published:
    """A published reach count of Fig. 6.1 (of 288 handovers) and ours, with the reason."""

    role: str
    pattern: str
    seed: int
    ours: int
    reason: str

    def __str__(self) -> str:
        return f"{self.role}-{self.pattern}:seed{self.seed}-ours{self.ours}"


FIG_6_1 = [
    Published("receiver", "Hand", 199, 231, LATE_RECEIVER),
    Published("receiver", "Short Face-Hand", 62, 41, LATE_RECEIVER),
    Published("receiver", "Face", 14, 6, LATE_RECEIVER),
    Published("receiver", "Long Face-Hand", 8, 6, LATE_RECEIVER),
    Published("giver", "Hand", 103, 121, GIVER_HAND),
    Published("giver", "Short Face-Hand", 87, 117, GIVER_TURN_LATE),
    Published("giver", "Face", 35, 17, GIVER_TURN_LATE),
    Published("giver", "Long Face-Hand", 26, 27, "within one handover"),
]


@pytest.mark.parametrize("fig", FIG_6_1, ids=str)
def test_fig_6_1_reach_count_beside_the_seeds(summary, fig):
    """The seed's count is its published share of 288 (``SEED_REACH``); ours differs by the
    stated gap for the stated reason (``fig.reason``)."""
    assert round(float(SEED_REACH[fig.role][fig.pattern]) * 288 / 100) == fig.seed
    gap = summary.counts["reach"][fig.role][fig.pattern] - fig.seed
    assert gap == fig.ours - fig.seed, (
        f"gap {gap:+d}, stated {fig.ours - fig.seed:+d}: {fig.reason}"
    )


def _reach_counts(annotations, role: str, window) -> Counter:
    """Reach patterns of ``role`` with the frames ``window(handover)`` picks."""
    out = Counter()
    for h in annotations.handovers:
        gaze = h.gaze(role)
        out[classify_reach([DEFAULT_RULE.target(gaze[i]) for i in window(h)])] += 1
    return out


def test_receiver_hand_231_vs_199_comes_from_the_late_receiver_reach(annotations, summary):
    """Fig. 6.1: receiver Hand 199 of 288 (69.1 %); ours 231 (80.2 %). Counting the frames
    where either person reaches (so the receiver's window starts with the giver's reach) turns
    56 of our Hand receivers into Face-Hand: 175, now below the seed's 199. The seed's window
    lies between the two, which no whole-frame window of the public files matches."""
    assert summary.counts["reach"]["receiver"]["Hand"] == 231

    def either_reaches(h):
        g, r = h.phase("giver"), h.phase("receiver")
        return [i for i in range(len(g)) if "reach" in (g[i], r[i])]

    union = _reach_counts(annotations, "receiver", either_reaches)
    assert union["Hand"] == 175 < 199 < 231
    assert union["Short Face-Hand"] == 95  # seed 62, ours 41: the same frames move


def test_giver_face_17_vs_35_comes_from_late_face_to_hand_turns(annotations, summary):
    """Fig. 6.1: giver Face 35 of 288 (12.2 %); ours 17 (5.9 %). Dropping the last two frames
    of each giver's own reach gives 27 Face and 88 Short Face-Hand (seed 87): the turns to the
    hand come at the reach's end. Our reach is not shortened to match: the seed's mean giver
    reach (8.10 frames) is already longer than ours (7.89)."""
    assert summary.counts["reach"]["giver"]["Face"] == 17

    def own_reach_but_last(k):
        def window(h):
            idx = [i for i, p in enumerate(h.phase("giver")) if p == "reach"]
            return idx[: len(idx) - k]

        return window

    cut = _reach_counts(annotations, "giver", own_reach_but_last(2))
    assert (cut["Face"], cut["Short Face-Hand"]) == (27, 88)
    assert 17 < cut["Face"] < 35


def test_giver_hand_121_vs_103_is_not_a_window_effect(annotations, summary):
    """Fig. 6.1: giver Hand 103; ours 121. The windows that move the other gaps leave it at
    114 (either person reaching) or 123 (own reach without its last two frames)."""
    assert summary.counts["reach"]["giver"]["Hand"] == 121

    def either_reaches(h):
        g, r = h.phase("giver"), h.phase("receiver")
        return [i for i in range(len(g)) if "reach" in (g[i], r[i])]

    def own_reach_but_last_two(h):
        idx = [i for i, p in enumerate(h.phase("giver")) if p == "reach"]
        return idx[:-2]

    assert _reach_counts(annotations, "giver", either_reaches)["Hand"] == 114
    assert _reach_counts(annotations, "giver", own_reach_but_last_two)["Hand"] == 123


@pytest.mark.parametrize(
    ("role", "seed", "ours"), [("giver", 8.10, 7.889), ("receiver", 7.53, 6.432)]
)
def test_fig_6_1_mean_reach_length_beside_the_seeds(summary, role, seed, ours):
    """Fig. 6.1's mean reach lengths (frames). Giver 7.89 vs 8.10; receiver 6.43 vs 7.53, the
    late receiver reach of ``LATE_RECEIVER``."""
    assert SEED_REACH_FRAMES[role] == seed
    assert summary.phase_frames[role]["reach"] == pytest.approx(ours, abs=1e-3)


# Section 6.4.2 / Fig. 6.5 (three phases), as worded there: (role, pattern, seed, ours %, why)
FIG_6_5 = [
    ("receiver", "Hand", "17.4", 17.4, "matches (50 of 288)"),
    ("giver", "Hand", "15.9", 17.0, "3 handovers more (49 vs 46)"),
    ("receiver", "Hand-Face", ">50", 63.5, "matches the bound"),
    ("giver", "Face-Hand-Face", ">40", 42.0, "matches the bound"),
    ("giver", "Hand-Face", "25", 26.4, "4 handovers more (76 vs 72)"),
    (
        "receiver",
        "Face-Hand-Face",
        "25",
        14.6,
        "fewer receivers glance at the face early in the reach (LATE_RECEIVER; Fig. 6.1's "
        "receiver Face-Hand 41 vs 62)",
    ),
]


@pytest.mark.parametrize(("role", "pattern", "seed", "ours", "why"), FIG_6_5)
def test_fig_6_5_three_phase_share_beside_the_seeds(summary, role, pattern, seed, ours, why):
    assert SEED_THREE_PHASE[role][pattern] == seed
    share = summary.three_phase[role][pattern]
    assert share == pytest.approx(ours, abs=0.05)
    if seed.startswith(">"):
        assert share > float(seed[1:]), why


def test_hand_face_is_the_most_humanlike_builtin_for_receivers(annotations):
    names = ["face", "hand", "face-hand-face", "hand-face", "face-hand-face-as-studied"]
    shares = {n: replay(annotations, load_behavior(n), "receiver").share for n in names}
    assert max(shares, key=shares.get) == "hand-face"
    assert shares["face-hand-face"] > shares["face-hand-face-as-studied"] > shares["face"]


def test_the_shipped_human_receiver_model_is_the_fit_of_the_data(annotations):
    shipped = load_behavior("human-receiver").human
    assert fit_human_model(annotations, "receiver") == shipped
