"""The seed's questionnaire (sections 6.3.2 and 6.4.4, after Zheng et al.), word for word, the
measures built from it, the instructions for each gaze mode, and the sheets written for a rendered
study (response CSV, Markdown questions, blind HTML pages)."""

from __future__ import annotations

import csv
import html
from pathlib import Path

from gazebot.apps.study.plan import Session

# Asked after every pair of handovers; answers are 1 (1st handover) or 2 (2nd handover).
QUESTIONS: dict[str, str] = {
    "q1": "Which handover did you like better? (1st or 2nd)",
    "q2": "Which handover seemed more friendly? (1st or 2nd)",
    "q3": "Which handover seemed more natural? (1st or 2nd)",
    "q4": "Which handover seemed more humanlike? (1st or 2nd)",
    "q5": (
        "Which handover made it easier to tell when, exactly, the robot wanted the giver to give "
        "the object? (1st or 2nd)"
    ),
}
COMMENT_QUESTION = "Any other comments (optional)"
# 6.4.5, the in-person study: "The only difference was in Question 5".
IN_PERSON_Q5 = (
    "Which handover made it easier to tell when, exactly, the robot wanted you to give the "
    "object? (1st or 2nd)"
)


def questions(mode: str = "video") -> dict[str, str]:
    """The five choice questions as asked in ``mode`` (``video`` or ``in-person``)."""
    if mode not in ("video", "in-person"):
        raise ValueError(f"questionnaire mode must be 'video' or 'in-person', got {mode!r}")
    return {**QUESTIONS, "q5": IN_PERSON_Q5} if mode == "in-person" else dict(QUESTIONS)


# Dependent measures: likability = mean of Q1, Q2; anthropomorphism = mean of Q3, Q4;
# timing communication = Q5.
MEASURES: dict[str, tuple[str, ...]] = {
    "likability": ("q1", "q2"),
    "anthropomorphism": ("q3", "q4"),
    "timing-communication": ("q5",),
}

# What the participant is told to watch, per gaze mode. The seed: "participants should pay close
# attention to the robot's head movement in the video" (6.3.2, a head with static eyes) and "...to
# the robot's eyes in the video" (6.4.4, eye gazes).
ATTENTION: dict[str, str] = {
    "head-only": "the robot's head movement",
    "eyes-only": "the robot's eyes",
    "head-and-eyes": "the robot's head movement and eyes",
}


def attention_caption(gaze_mode: str) -> str:
    """The caption of every video: what to pay close attention to (see :data:`ATTENTION`)."""
    if gaze_mode not in ATTENTION:
        raise ValueError(f"unknown gaze mode {gaze_mode!r}; expected one of {list(ATTENTION)}")
    return f"Please pay close attention to {ATTENTION[gaze_mode]} in the video."


def instructions(gaze_mode: str = "head-and-eyes") -> str:
    """The study's instructions, naming the head or the eyes to match ``gaze_mode``."""
    return (
        "In each session you will watch two handover videos, one after the other. "
        f"{attention_caption(gaze_mode)} After both videos, answer every question with 1st (the "
        "1st handover) or 2nd (the 2nd handover)."
    )


INSTRUCTIONS = instructions()


def write_questionnaire(plan: list[Session], out_dir: str | Path) -> tuple[Path, Path]:
    """The response sheet (CSV, one row per participant and session, answers blank) and the
    questions as Markdown (video wording, and the in-person wording of question 5)."""
    out_dir = Path(out_dir)
    gaze_mode = plan[0].gaze_mode if plan else "head-and-eyes"
    csv_path = out_dir / "questionnaire.csv"
    cols = [
        "participant",
        "session",
        "condition",
        "level",
        "first",
        "second",
        "video",
        *QUESTIONS,
        "comments",
    ]
    with csv_path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(cols)
        for s in sorted(plan, key=lambda s: (s.participant, s.session)):
            video = f"participants/P{s.participant:02d}/session-{s.session:02d}.mp4"
            writer.writerow(
                [
                    s.participant,
                    s.session,
                    s.condition,
                    s.level,
                    s.first,
                    s.second,
                    video,
                    *([""] * len(QUESTIONS)),
                    "",
                ]
            )
    md_path = out_dir / "questionnaire.md"
    lines = [
        "# Handover study questionnaire",
        "",
        instructions(gaze_mode),
        "",
        "After each session (two handovers):",
        "",
    ]
    lines += [f"{k + 1}. {q}" for k, q in enumerate(QUESTIONS.values())]
    lines += [f"{len(QUESTIONS) + 1}. {COMMENT_QUESTION}", ""]
    lines += [f"In person, question 5 reads: {IN_PERSON_Q5}", ""]
    lines += [
        "Run the study in a browser with `gazebot study serve DIR` and `gazebot study export DIR",
        "--out responses.csv`, or record the answers (1 or 2) in `questionnaire.csv` columns",
        "q1..q5; then run `gazebot study analyze responses.csv`.",
        "",
    ]
    md_path.write_text("\n".join(lines), encoding="utf-8")
    return csv_path, md_path


def write_participant_page(
    participant: int, session_files: list[Path], pdir: Path, gaze_mode: str = "head-and-eyes"
) -> Path:
    """A blind offline HTML page: the participant's sessions in order, each with its video and
    the five questions (behavior names are not shown). It saves nothing: ``gazebot study serve``
    runs the study with stored answers."""
    parts = [
        "<!DOCTYPE html><html><head><meta charset='utf-8'>",
        f"<title>Participant {participant}</title></head><body>",
        f"<h1>Participant {participant}</h1><p>{html.escape(instructions(gaze_mode))}</p>",
    ]
    for k, f in enumerate(session_files, start=1):
        parts.append(f"<h2>Session {k}</h2><video controls width='640' src='{f.name}'></video><ol>")
        for q, text in QUESTIONS.items():
            parts.append(
                f"<li>{html.escape(text)} "
                f"<label><input type='radio' name='s{k}{q}' value='1'>1st</label> "
                f"<label><input type='radio' name='s{k}{q}' value='2'>2nd</label></li>"
            )
        parts.append(f"<li>{html.escape(COMMENT_QUESTION)} <input name='s{k}c' size='60'></li>")
        parts.append("</ol>")
    parts.append("</body></html>")
    path = pdir / "index.html"
    path.write_text("\n".join(parts), encoding="utf-8")
    return path
