"""The study server under abuse: half-sent requests ("slowloris") do not stop participants, and
the answers file (every participant's link token, the CSRF key) is readable by its owner only."""

from __future__ import annotations

import os
import sqlite3
import stat
import time
from pathlib import Path

import pytest
from slowloris import Slowloris, timed_get
from study_web import StudyServer, render_tiny_study

from gazebot.apps.study.folder import load_study
from gazebot.apps.study.store import ResponseStore
from gazebot.apps.study.web.server import ConnectionLimits, raise_open_file_limit

ATTACKERS = 200  # twice waitress's default connection_limit, which they used to exhaust
HOLD_S = 60.0  # s the attack is held
GET_TIMEOUT_S = 10.0  # s a participant's request may take
TRICKLE_S = 2.0  # s between the attackers' header lines (a request's time may come on top)


@pytest.fixture(scope="module")
def study_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("abuse") / "study"
    render_tiny_study(out)
    return out


def test_200_half_sent_requests_held_60_s_do_not_stop_a_participant(study_dir):
    """The attack is held for 60 s (the server closes none of the half-sent requests: each
    sends a header line every few seconds) while a participant's five requests, spread over
    that minute, are each answered, all 200 still connected when the answer came. With
    waitress's defaults the same attack leaves every one of them unanswered: it stops
    accepting at 100 connections. An answer may take up to GET_TIMEOUT_S (a busy host stalls
    the server or this process for seconds): what counts is that it comes while the attack
    holds, not how fast."""
    # The attackers' lines never stop for channel_timeout_s, even while a request waits.
    assert GET_TIMEOUT_S + TRICKLE_S < ConnectionLimits().channel_timeout_s
    with StudyServer(study_dir) as server:
        url = f"{server.base}/healthz"
        assert timed_get(url, 10.0) is not None  # up, and warm
        with Slowloris("127.0.0.1", server.port, ATTACKERS) as attack:
            start = time.monotonic()
            times = []
            while time.monotonic() - start < HOLD_S:
                attack.trickle()  # a header line each: never idle long enough to be closed
                if time.monotonic() - start >= len(times) * HOLD_S / 5:
                    times.append(timed_get(url, GET_TIMEOUT_S))
                    # Answered while every attacker was still connected: the attack held.
                    assert attack.alive() == ATTACKERS, times
                    attack.trickle()
                time.sleep(TRICKLE_S)
            assert attack.alive() == ATTACKERS  # the attack was on all along
        assert len(times) == 5 and None not in times, times


def test_limits_leave_room_for_many_more_connections_than_one_attack():
    limits = ConnectionLimits()
    options = limits.waitress_options()
    assert options["connection_limit"] >= 5 * ATTACKERS
    assert options["asyncore_use_poll"] is True  # select() cannot watch sockets numbered >= 1024
    assert 0 < limits.cleanup_interval_s < limits.channel_timeout_s <= 60
    assert raise_open_file_limit(64) >= 64


def _mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def _written_while_held(db) -> None:
    """A write to ``db`` while another connection holds it open: SQLite removes the ``-wal``
    and ``-shm`` when the last connection closes, so they are looked at while one is open."""
    holder = sqlite3.connect(db)
    try:
        holder.execute("SELECT COUNT(*) FROM participants").fetchone()
        store = ResponseStore(db)
        store.give_consent(len(store.all_progress()) + 1)
        store.links([1, 2])
        for suffix in ("", "-wal", "-shm"):
            path = Path(f"{db}{suffix}")
            assert path.exists(), path.name  # WAL mode: all three are there now
            assert _mode(path) == 0o600, path.name
    finally:
        holder.close()


def test_answers_file_and_its_wal_and_shm_are_created_owner_only(tmp_path):
    old = os.umask(0o022)  # a usual umask, which would make new files 0644
    try:
        db = tmp_path / "responses.sqlite"
        ResponseStore(db)
        _written_while_held(db)
    finally:
        os.umask(old)


def test_an_older_world_readable_answers_file_is_made_owner_only(tmp_path):
    db = tmp_path / "responses.sqlite"
    ResponseStore(db).give_consent(1)
    os.chmod(db, 0o644)  # as a gazebot before this change left it
    _written_while_held(db)
    assert ResponseStore(db).progress(1).consent_at is not None  # the answers are still there


def test_a_served_study_answers_file_is_owner_only(study_dir):
    with StudyServer(study_dir) as server:
        assert timed_get(f"{server.base}/healthz", 10.0) is not None
        db = load_study(study_dir).database
        assert _mode(db) == 0o600
        for suffix in ("-wal", "-shm"):
            side = db.with_name(db.name + suffix)
            if side.exists():  # the server holds them open while it runs
                assert _mode(side) == 0o600, side.name
