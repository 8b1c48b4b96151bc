"""``gazebot study export``: the answers stored by ``gazebot study serve`` as the responses CSV
that ``gazebot study analyze`` reads (:mod:`gazebot.apps.study.analysis`), with timestamps, the time
spent per session and the seed's reach-start time of both handovers (giver's reach start minus
the robot's, s; empty when unknown: for a video session the rendered videos', for an in-person
session the times the experimenter measured), and the in-person familiarity answer (1-5), which
``gazebot study in-person`` analyses (:mod:`gazebot.apps.study.in_person`).

A study with a study file (``DIR/study.yaml``) gets more columns after :data:`EXPORT_COLUMNS`:
``external_id`` (the recruiting service's id, from the entry link), ``attention_failures`` (the
ids of the attention checks the participant failed, ``;``-separated) and one column per item
(its id): a session item's answer on its session's row, a page item's on every row of the
participant. Since a participant an attention check ended may have answered no session, the
same per-participant answers also go to ``OUT-participants.csv``, one row per participant who
gave consent."""

from __future__ import annotations

import csv
from datetime import datetime, timezone
from pathlib import Path

from gazebot.apps.study.csvio import check_output_file
from gazebot.apps.study.folder import load_study
from gazebot.apps.study.store import QUESTION_KEYS, ResponseStore, session_page
from gazebot.apps.study.study_file import DEFAULT, StudyFile, study_file_of
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


STUDY_FILE_COLUMNS = ("external_id", "attention_failures")  # then one column per item
PARTICIPANT_COLUMNS = ("participant", "external_id", "status", "attention_failures")


def participants_file(out: Path) -> Path:
    """Where the per-participant answers of a study file's study go, beside ``out``."""
    return out.with_name(f"{out.stem}-participants{out.suffix}")


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
    sf = study_file_of(study.root)
    extra = _ItemColumns(store, sf) if sf is not DEFAULT else None
    by_key = {(s.participant, s.session): s for s in study.plan}
    two_groups = len({a.mode for a in answers}) > 1
    with atomic_path(out) as tmp, tmp.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(EXPORT_COLUMNS + (extra.columns if extra else ()))
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
                    *(extra.session_row(a.participant, a.session) if extra else ()),
                ]
            )
    if extra is not None:
        extra.write_participants(participants_file(out))
    return out, len(answers)


class _ItemColumns:
    """The study file's answers of every participant, as export columns."""

    def __init__(self, store: ResponseStore, sf: StudyFile) -> None:
        self.store = store
        self.session_items = [i.id for i in sf.session_items]
        self.page_items = [i.id for p in sf.pages for i in p.items]
        self.columns = STUDY_FILE_COLUMNS + tuple(self.session_items + self.page_items)
        self.values: dict[tuple[int, str], dict[str, str]] = {}
        for a in store.item_answers():
            self.values.setdefault((a.participant, a.page), {})[a.item] = a.value
        self.page_of = {i.id: p.id for p in sf.pages for i in p.items}
        self.external = store.external_ids()
        self.failed: dict[int, list[str]] = {}
        for f in store.attention_failures():
            self.failed.setdefault(f.participant, []).append(f.item)
        self.sf = sf

    def _participant_cells(self, participant: int) -> list[str]:
        return [
            self.external.get(participant, ""),
            ";".join(self.failed.get(participant, [])),
        ]

    def _page_cells(self, participant: int) -> list[str]:
        return [
            self.values.get((participant, self.page_of[i]), {}).get(i, "") for i in self.page_items
        ]

    def session_row(self, participant: int, session: int) -> list[str]:
        """The extra cells of one session's row."""
        mine = self.values.get((participant, session_page(session)), {})
        return [
            *self._participant_cells(participant),
            *(mine.get(i, "") for i in self.session_items),
            *self._page_cells(participant),
        ]

    def write_participants(self, path: Path) -> None:
        """One row per participant who gave consent: the id, how far they got (``started``;
        ``finished``: every session and page answered; ``ended``: an attention check ended the
        study), the checks failed and every page item's answer."""
        with atomic_path(path) as tmp, tmp.open("w", newline="", encoding="utf-8") as fh:
            writer = csv.writer(fh)
            writer.writerow(PARTICIPANT_COLUMNS + tuple(self.page_items))
            for prog in self.store.all_progress():
                if prog.consent_at is None:
                    continue
                p = prog.participant
                after = all(pg.id in prog.pages for pg in self.sf.pages_at("after"))
                status = (
                    "ended"
                    if self.sf.ends_on(prog.failed_items)
                    else "finished"
                    if prog.finished_at is not None and after
                    else "started"
                )
                cells = self._participant_cells(p)
                writer.writerow([p, cells[0], status, cells[1], *self._page_cells(p)])
