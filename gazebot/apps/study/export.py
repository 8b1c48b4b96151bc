"""``gazebot study export``: the answers stored by ``gazebot study serve`` as the responses CSV
that ``gazebot study analyze`` reads (:mod:`gazebot.apps.study.analysis`), with timestamps, the time
spent per session and the seed's reach-start time of both handovers (giver's reach start minus
the robot's, s; empty when unknown: for a video session the rendered videos', for an in-person
session the times the experimenter measured), and the in-person familiarity answer (1-5), which
``gazebot study in-person`` analyses (:mod:`gazebot.apps.study.in_person`)."""

from __future__ import annotations

import csv
from datetime import datetime, timezone
from pathlib import Path

from gazebot.apps.study.csvio import check_output_file
from gazebot.apps.study.folder import load_study
from gazebot.apps.study.store import QUESTION_KEYS
from gazebot.apps.study.video_times import fmt_seconds
from gazebot.io.atomic import atomic_path

EXPORT_COLUMNS = (
    "participant",
    "session",
    "condition",
    "level",
    "first",
    "second",
    *QUESTION_KEYS,
    "comments",
    "group",
    "mode",
    "scene",
    "robot",
    "gaze_mode",
    "first_reach_start_time",
    "second_reach_start_time",
    "familiarity",
    "shown_at",
    "submitted_at",
    "seconds",
)


def _iso(t: float | None) -> str:
    if t is None:
        return ""
    return datetime.fromtimestamp(t, timezone.utc).isoformat(timespec="milliseconds")


def export_responses(
    study_dir: str | Path, out: str | Path, include_practice: bool = False
) -> tuple[Path, int]:
    """Write the stored answers of the study in ``study_dir`` to ``out`` (CSV, one row per
    answered session, by participant and session; columns :data:`EXPORT_COLUMNS`); return the
    path and the number of rows. ``group`` is the participant's mode (``video``/``in-person``)
    when the study has both, so that ``analyze`` compares them as independent groups, else
    empty. ``seconds``: from first showing the session page (in person: the experimenter's page for
    that pair) to the submit. The practice session (session 0) is left out unless
    ``include_practice``; ``analyze`` would count it as a study session."""
    study = load_study(study_dir)
    out = check_output_file(out, "responses", ".csv")
    if not study.database.is_file():
        raise ValueError(f"{study.root}: no answers yet (no {study.database.name})")
    store = study.store()
    answers = store.answers(include_practice=include_practice)
    familiarity = store.familiarity()
    measured = store.reach_starts()
    by_key = {(s.participant, s.session): s for s in study.plan}
    two_groups = len({a.mode for a in answers}) > 1
    with atomic_path(out) as tmp, tmp.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(EXPORT_COLUMNS)
        for a in answers:
            s = by_key.get((a.participant, a.session))
            if s is None and a.session != 0:
                raise ValueError(
                    f"{study.database}: answer for participant {a.participant} session "
                    f"{a.session}, which the plan does not have"
                )
            seconds = a.seconds
            try:
                shown = study.session_videos(a.participant, a.session)
            except KeyError:
                shown = None
            if a.mode == "in-person":  # live handovers: what was measured, not the videos'
                times = measured.get((a.participant, a.session), (None, None))
            else:
                times = (
                    shown.first_reach_start_time if shown else None,
                    shown.second_reach_start_time if shown else None,
                )
            fam = familiarity.get(a.participant)
            writer.writerow(
                [
                    a.participant,
                    a.session,
                    s.condition if s else "",
                    s.level if s else "",
                    s.first if s else "practice",
                    s.second if s else "practice",
                    *(a.answers[q] for q in QUESTION_KEYS),
                    a.comment,
                    a.mode if two_groups else "",
                    a.mode,
                    s.scene if s else "",
                    s.robot if s else "",
                    study.gaze_mode,
                    fmt_seconds(times[0]),
                    fmt_seconds(times[1]),
                    "" if fam is None else fam,
                    _iso(a.shown_at),
                    _iso(a.submitted_at),
                    "" if seconds is None else f"{seconds:.3f}",
                ]
            )
    return out, len(answers)
