"""The answers of a study run in the browser: one SQLite file, ``DIR/responses.sqlite``.

Every write is one transaction committed before the HTTP response goes out, in WAL mode with
``synchronous=FULL``: an answer the participant saw accepted survives a killed server (and a
power cut). A participant's place in the study is derived from what is stored (consent given,
instructions read, the sessions answered), never kept in the server's memory, so a reload, a
closed tab or a restarted server resumes exactly there.

Tables:

- ``participants(participant, mode, consent_at, instructions_at, finished_at)``: ``mode`` is
  ``video`` (the participant answers in the browser) or ``in-person`` (the experimenter enters
  the answers after each live pair); set by the first step taken.
- ``answers(participant, session, q1..q5, comment, mode, shown_at, submitted_at)``: one row per
  answered session, session 0 being the practice; the primary key (participant, session) makes a
  double submit record once (the first one wins).
- ``views(participant, session, shown_at)``: when a session page was first shown, for the time
  spent per session.
- ``links(participant, token)``: each participant's random link token (made once, kept across
  restarts, so a link handed out stays valid).
- ``secrets(name, value)``: the server's secrets (the CSRF key), made once.
- ``familiarity(participant, answer, answered_at)``: the in-person study's familiarity question
  (1-5, seed 6.3.3 and 6.4.5: "How familiar are you with a collaborative robot (such as the one
  shown)?"), entered by the experimenter with the first live pair; a later entry corrects it.
- ``reach_starts(participant, session, first_s, second_s)``: the giver's reach-start time in each
  live handover of an in-person session (s, the human's reach start minus the robot's; NULL: not
  measured), entered by the experimenter with the session's answers.

A study file (:mod:`gazebot.apps.study.study_file`) adds:

- ``items(participant, page, item, value, submitted_at)``: every answer to a study file's items
  (Likert, free text, choice, number, attention check), ``page`` being a page's id or
  ``session-K`` for the items asked after session ``K``; values are text as given.
- ``pages(participant, page, submitted_at)``: the study file's pages a participant has done.
- ``attention(participant, page, item, given, expected, at)``: each failed attention check.
- ``entries(participant, external_id, at)``: the participants the public entry link assigned,
  with the recruiting service's participant id (one plan row per external id).

The file and its ``-wal``/``-shm`` hold every participant's link token and the CSRF key: they are
readable by their owner only (0600).

Times are UTC seconds since the epoch (floats).
"""

from __future__ import annotations

import os
import secrets
import sqlite3
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

QUESTION_KEYS = ("q1", "q2", "q3", "q4", "q5")
MODES = ("video", "in-person")

_SCHEMA = """
CREATE TABLE IF NOT EXISTS participants (
    participant INTEGER PRIMARY KEY,
    mode TEXT NOT NULL CHECK (mode IN ('video', 'in-person')),
    consent_at REAL,
    instructions_at REAL,
    finished_at REAL
);
CREATE TABLE IF NOT EXISTS answers (
    participant INTEGER NOT NULL,
    session INTEGER NOT NULL,
    q1 INTEGER NOT NULL CHECK (q1 IN (1, 2)),
    q2 INTEGER NOT NULL CHECK (q2 IN (1, 2)),
    q3 INTEGER NOT NULL CHECK (q3 IN (1, 2)),
    q4 INTEGER NOT NULL CHECK (q4 IN (1, 2)),
    q5 INTEGER NOT NULL CHECK (q5 IN (1, 2)),
    comment TEXT NOT NULL DEFAULT '',
    mode TEXT NOT NULL,
    shown_at REAL,
    submitted_at REAL NOT NULL,
    PRIMARY KEY (participant, session)
);
CREATE TABLE IF NOT EXISTS views (
    participant INTEGER NOT NULL,
    session INTEGER NOT NULL,
    shown_at REAL NOT NULL,
    PRIMARY KEY (participant, session)
);
CREATE TABLE IF NOT EXISTS links (
    participant INTEGER PRIMARY KEY,
    token TEXT NOT NULL UNIQUE
);
CREATE TABLE IF NOT EXISTS secrets (
    name TEXT PRIMARY KEY,
    value TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS familiarity (
    participant INTEGER PRIMARY KEY,
    answer INTEGER NOT NULL CHECK (answer BETWEEN 1 AND 5),
    answered_at REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS reach_starts (
    participant INTEGER NOT NULL,
    session INTEGER NOT NULL,
    first_s REAL,
    second_s REAL,
    PRIMARY KEY (participant, session)
);
CREATE TABLE IF NOT EXISTS items (
    participant INTEGER NOT NULL,
    page TEXT NOT NULL,
    item TEXT NOT NULL,
    value TEXT NOT NULL,
    submitted_at REAL NOT NULL,
    PRIMARY KEY (participant, page, item)
);
CREATE TABLE IF NOT EXISTS pages (
    participant INTEGER NOT NULL,
    page TEXT NOT NULL,
    submitted_at REAL NOT NULL,
    PRIMARY KEY (participant, page)
);
CREATE TABLE IF NOT EXISTS attention (
    participant INTEGER NOT NULL,
    page TEXT NOT NULL,
    item TEXT NOT NULL,
    given TEXT NOT NULL,
    expected TEXT NOT NULL,
    at REAL NOT NULL,
    PRIMARY KEY (participant, page, item)
);
CREATE TABLE IF NOT EXISTS entries (
    participant INTEGER PRIMARY KEY,
    external_id TEXT NOT NULL UNIQUE,
    at REAL NOT NULL
);
"""
PRIVATE_MODE = 0o600  # the answers file and SQLite's -wal and -shm beside it


@dataclass(frozen=True)
class Answer:
    """One answered session (session 0: the practice)."""

    participant: int
    session: int
    answers: dict[str, int]
    comment: str
    mode: str
    shown_at: float | None
    submitted_at: float

    @property
    def seconds(self) -> float | None:
        """Time from first showing the session to submitting it (None if never shown)."""
        return None if self.shown_at is None else self.submitted_at - self.shown_at


@dataclass(frozen=True)
class Progress:
    """Where a participant is: the steps done and the answered sessions."""

    participant: int
    mode: str | None
    consent_at: float | None
    instructions_at: float | None
    finished_at: float | None
    answered: tuple[int, ...]
    last_activity: float | None
    pages: tuple[str, ...] = ()  # the study file's pages done
    failed_items: tuple[str, ...] = ()  # the attention checks failed (item ids)


@dataclass(frozen=True)
class ItemAnswer:
    """One answer to a study file's item: ``page`` is the page's id or ``session-K``."""

    participant: int
    page: str
    item: str
    value: str
    submitted_at: float


@dataclass(frozen=True)
class AttentionFailure:
    """An attention check answered otherwise than its required answer."""

    participant: int
    page: str
    item: str
    given: str
    expected: str
    at: float


def _make_private(path: Path) -> None:
    """Create ``path`` readable by its owner only, or tighten an existing one and its
    ``-wal``/``-shm``. SQLite creates the ``-wal`` and ``-shm`` files with the database file's
    permission bits, so a 0600 database gets 0600 companions whatever the umask."""
    fd = os.open(path, os.O_RDWR | os.O_CREAT, PRIVATE_MODE)
    os.close(fd)
    for p in (path, Path(f"{path}-wal"), Path(f"{path}-shm")):
        if p.exists() and (p.stat().st_mode & 0o777) != PRIVATE_MODE:
            os.chmod(p, PRIVATE_MODE)


def session_page(session: int) -> str:
    """The page name under which the study file's items of session ``session`` are stored."""
    return f"session-{session}"


class ResponseStore:
    """The study's SQLite file. Each method opens its own connection (cheap, and safe from any
    server thread) and commits before returning."""

    def __init__(self, path: str | Path, timeout_s: float = 10.0) -> None:
        self.path = Path(path)
        self.timeout_s = timeout_s
        # Writers of this process take turns here: SQLite's own busy handler would put a
        # waiting writer to sleep for milliseconds; other processes still meet its lock.
        self._write_lock = threading.Lock()
        _make_private(self.path)
        with self._connect() as con:
            con.execute("PRAGMA journal_mode=WAL")
            con.executescript(_SCHEMA)

    @contextmanager
    def _connect(self) -> Iterator[sqlite3.Connection]:
        con = sqlite3.connect(self.path, timeout=self.timeout_s, isolation_level=None)
        try:
            con.execute("PRAGMA synchronous=FULL")
            con.execute("PRAGMA foreign_keys=ON")
            yield con
        finally:
            con.close()

    @contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        with self._write_lock, self._connect() as con:
            con.execute("BEGIN IMMEDIATE")
            try:
                yield con
            except BaseException:
                con.execute("ROLLBACK")
                raise
            con.execute("COMMIT")

    def _ensure(self, con: sqlite3.Connection, participant: int, mode: str) -> str:
        """Create the participant's row in ``mode`` if new; return the stored mode."""
        if mode not in MODES:
            raise ValueError(f"mode must be one of {MODES}, got {mode!r}")
        con.execute(
            "INSERT INTO participants (participant, mode) VALUES (?, ?) "
            "ON CONFLICT (participant) DO NOTHING",
            (participant, mode),
        )
        return con.execute(
            "SELECT mode FROM participants WHERE participant = ?", (participant,)
        ).fetchone()[0]

    def give_consent(self, participant: int, mode: str = "video", now: float | None = None) -> None:
        """Record consent (the first time only)."""
        with self._transaction() as con:
            self._ensure(con, participant, mode)
            con.execute(
                "UPDATE participants SET consent_at = ? "
                "WHERE participant = ? AND consent_at IS NULL",
                (now or time.time(), participant),
            )

    def read_instructions(self, participant: int, now: float | None = None) -> None:
        """Record that the instructions were read (the first time only; needs consent)."""
        with self._transaction() as con:
            con.execute(
                "UPDATE participants SET instructions_at = ? "
                "WHERE participant = ? AND instructions_at IS NULL AND consent_at IS NOT NULL",
                (now or time.time(), participant),
            )

    def mark_shown(self, participant: int, session: int, now: float | None = None) -> None:
        """Remember when a session page was first shown."""
        with self._transaction() as con:
            con.execute(
                "INSERT INTO views (participant, session, shown_at) VALUES (?, ?, ?) "
                "ON CONFLICT DO NOTHING",
                (participant, session, now or time.time()),
            )

    def submit(
        self,
        participant: int,
        session: int,
        answers: dict[str, int],
        comment: str = "",
        mode: str = "video",
        last_session: int | None = None,
        now: float | None = None,
        items: dict[str, str] | None = None,
        failed: dict[str, tuple[str, str]] | None = None,
    ) -> bool:
        """Store one session's answers; ``True`` if stored now, ``False`` if that session was
        already answered (a double submit: the first answers stay). ``last_session``: the plan's
        last session, whose answer marks the participant finished. A participant answering in
        another mode than their first step raises ``ValueError``. ``items``: the study file's
        items asked after the pair (item id -> value), stored under page ``session-K`` in the
        same transaction; ``failed``: its attention checks failed (item -> (given, expected))."""
        values = [int(answers[q]) for q in QUESTION_KEYS]
        if any(v not in (1, 2) for v in values):
            raise ValueError(f"answers must be 1 or 2, got {answers}")
        now = now or time.time()
        with self._transaction() as con:
            stored_mode = self._ensure(con, participant, mode)
            if stored_mode != mode:
                raise ValueError(f"participant {participant} takes part {stored_mode}, not {mode}")
            shown = con.execute(
                "SELECT shown_at FROM views WHERE participant = ? AND session = ?",
                (participant, session),
            ).fetchone()
            cur = con.execute(
                "INSERT INTO answers (participant, session, q1, q2, q3, q4, q5, comment, mode, "
                "shown_at, submitted_at) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?) "
                "ON CONFLICT (participant, session) DO NOTHING",
                (participant, session, *values, comment, mode, shown[0] if shown else None, now),
            )
            stored = cur.rowcount == 1
            if stored:
                self._put_items(con, participant, session_page(session), items, failed, now)
            if stored and last_session is not None and session == last_session:
                con.execute(
                    "UPDATE participants SET finished_at = ? WHERE participant = ?",
                    (now, participant),
                )
        return stored

    @staticmethod
    def _put_items(
        con: sqlite3.Connection,
        participant: int,
        page: str,
        items: dict[str, str] | None,
        failed: dict[str, tuple[str, str]] | None,
        now: float,
    ) -> None:
        for item, value in (items or {}).items():
            con.execute(
                "INSERT INTO items (participant, page, item, value, submitted_at) "
                "VALUES (?, ?, ?, ?, ?) ON CONFLICT DO NOTHING",
                (participant, page, item, str(value), now),
            )
        for item, (given, expected) in (failed or {}).items():
            con.execute(
                "INSERT INTO attention (participant, page, item, given, expected, at) "
                "VALUES (?, ?, ?, ?, ?, ?) ON CONFLICT DO NOTHING",
                (participant, page, item, given, expected, now),
            )

    def submit_page(
        self,
        participant: int,
        page: str,
        items: dict[str, str],
        failed: dict[str, tuple[str, str]] | None = None,
        now: float | None = None,
    ) -> bool:
        """Store the answers to one of the study file's pages (item id -> value) and its failed
        attention checks, once: ``False`` if the page was already done (the first answers
        stay). Needs the participant's consent (``ValueError`` without)."""
        now = now or time.time()
        with self._transaction() as con:
            row = con.execute(
                "SELECT consent_at FROM participants WHERE participant = ?", (participant,)
            ).fetchone()
            if row is None or row[0] is None:
                raise ValueError(f"participant {participant} has not given consent")
            cur = con.execute(
                "INSERT INTO pages (participant, page, submitted_at) VALUES (?, ?, ?) "
                "ON CONFLICT DO NOTHING",
                (participant, page, now),
            )
            if cur.rowcount != 1:
                return False
            self._put_items(con, participant, page, items, failed, now)
        return True

    def assign_entry(
        self, external_id: str, participants: list[int], now: float | None = None
    ) -> int | None:
        """The participant (plan row) of ``external_id``: the one it was given before, else the
        first of ``participants`` (in order) nobody has taken (no entry, no step taken through
        its own link), now recorded as this id's; ``None`` when every row is taken."""
        with self._transaction() as con:
            row = con.execute(
                "SELECT participant FROM entries WHERE external_id = ?", (external_id,)
            ).fetchone()
            if row is not None:
                return int(row[0])
            taken = {r[0] for r in con.execute("SELECT participant FROM entries")}
            taken |= {r[0] for r in con.execute("SELECT participant FROM participants")}
            free = next((p for p in participants if p not in taken), None)
            if free is not None:
                con.execute(
                    "INSERT INTO entries (participant, external_id, at) VALUES (?, ?, ?)",
                    (free, external_id, now or time.time()),
                )
        return free

    def external_ids(self) -> dict[int, str]:
        """The recruiting service's id of each participant the entry link assigned."""
        with self._connect() as con:
            return dict(con.execute("SELECT participant, external_id FROM entries").fetchall())

    def item_answers(self) -> list[ItemAnswer]:
        """Every answer to a study file's item, by participant, page and item."""
        with self._connect() as con:
            rows = con.execute(
                "SELECT participant, page, item, value, submitted_at FROM items "
                "ORDER BY participant, page, item"
            ).fetchall()
        return [ItemAnswer(*r) for r in rows]

    def attention_failures(self) -> list[AttentionFailure]:
        """Every failed attention check, by participant and time."""
        with self._connect() as con:
            rows = con.execute(
                "SELECT participant, page, item, given, expected, at FROM attention "
                "ORDER BY participant, at, page, item"
            ).fetchall()
        return [AttentionFailure(*r) for r in rows]

    def links(self, participants: list[int], nbytes: int = 18) -> dict[int, str]:
        """Each participant's link token, a random one made (``nbytes`` random bytes) for a
        participant who has none yet."""
        with self._transaction() as con:
            for p in participants:
                con.execute(
                    "INSERT INTO links (participant, token) VALUES (?, ?) "
                    "ON CONFLICT (participant) DO NOTHING",
                    (p, secrets.token_urlsafe(nbytes)),
                )
            rows = con.execute("SELECT participant, token FROM links").fetchall()
        wanted = set(participants)
        return {p: t for p, t in rows if p in wanted}

    def secret(self, name: str, nbytes: int = 32) -> bytes:
        """The server secret ``name`` (random, made on first use, then kept)."""
        with self._transaction() as con:
            con.execute(
                "INSERT INTO secrets (name, value) VALUES (?, ?) ON CONFLICT (name) DO NOTHING",
                (name, secrets.token_hex(nbytes)),
            )
            value = con.execute("SELECT value FROM secrets WHERE name = ?", (name,)).fetchone()
        return bytes.fromhex(value[0])

    def progress(self, participant: int) -> Progress:
        """The participant's stored progress (all empty for one who has not started)."""
        with self._connect() as con:
            row = con.execute(
                "SELECT mode, consent_at, instructions_at, finished_at FROM participants "
                "WHERE participant = ?",
                (participant,),
            ).fetchone()
            sessions = con.execute(
                "SELECT session, submitted_at FROM answers WHERE participant = ? ORDER BY session",
                (participant,),
            ).fetchall()
            pages = con.execute(
                "SELECT page, submitted_at FROM pages WHERE participant = ? ORDER BY submitted_at",
                (participant,),
            ).fetchall()
            failed = con.execute(
                "SELECT item FROM attention WHERE participant = ? ORDER BY at", (participant,)
            ).fetchall()
        mode, consent, instr, finished = row if row else (None, None, None, None)
        done = [t for _, t in sessions] + [t for _, t in pages]
        times = [t for t in (consent, instr, *done) if t is not None]
        return Progress(
            participant=participant,
            mode=mode,
            consent_at=consent,
            instructions_at=instr,
            finished_at=finished,
            answered=tuple(s for s, _ in sessions),
            last_activity=max(times) if times else None,
            pages=tuple(p for p, _ in pages),
            failed_items=tuple(r[0] for r in failed),
        )

    def all_progress(self) -> list[Progress]:
        """Progress of every participant who has started, by participant number."""
        with self._connect() as con:
            ids = [r[0] for r in con.execute("SELECT participant FROM participants ORDER BY 1")]
        return [self.progress(p) for p in ids]

    def set_familiarity(self, participant: int, answer: int, now: float | None = None) -> None:
        """Record (or correct) the participant's familiarity answer, 1-5."""
        if answer not in range(1, 6):
            raise ValueError(f"familiarity must be 1-5, got {answer!r}")
        with self._transaction() as con:
            con.execute(
                "INSERT INTO familiarity (participant, answer, answered_at) VALUES (?, ?, ?) "
                "ON CONFLICT (participant) DO UPDATE SET answer = excluded.answer, "
                "answered_at = excluded.answered_at",
                (participant, answer, now or time.time()),
            )

    def familiarity(self) -> dict[int, int]:
        """Every recorded familiarity answer by participant."""
        with self._connect() as con:
            return dict(con.execute("SELECT participant, answer FROM familiarity").fetchall())

    def set_reach_starts(
        self, participant: int, session: int, first_s: float | None, second_s: float | None
    ) -> None:
        """Record the measured reach-start times (s) of a session's two live handovers."""
        with self._transaction() as con:
            con.execute(
                "INSERT INTO reach_starts (participant, session, first_s, second_s) "
                "VALUES (?, ?, ?, ?) ON CONFLICT (participant, session) DO UPDATE SET "
                "first_s = excluded.first_s, second_s = excluded.second_s",
                (participant, session, first_s, second_s),
            )

    def reach_starts(self) -> dict[tuple[int, int], tuple[float | None, float | None]]:
        """Measured reach-start times by (participant, session)."""
        with self._connect() as con:
            rows = con.execute(
                "SELECT participant, session, first_s, second_s FROM reach_starts"
            ).fetchall()
        return {(p, k): (a, b) for p, k, a, b in rows}

    def answers(self, include_practice: bool = False) -> list[Answer]:
        """Every stored answer by (participant, session)."""
        with self._connect() as con:
            rows = con.execute(
                "SELECT participant, session, q1, q2, q3, q4, q5, comment, mode, shown_at, "
                "submitted_at FROM answers WHERE session >= ? ORDER BY participant, session",
                (0 if include_practice else 1,),
            ).fetchall()
        return [
            Answer(
                participant=r[0],
                session=r[1],
                answers=dict(zip(QUESTION_KEYS, r[2:7], strict=True)),
                comment=r[7],
                mode=r[8],
                shown_at=r[9],
                submitted_at=r[10],
            )
            for r in rows
        ]
