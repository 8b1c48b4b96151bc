"""A real ``gazebot study serve`` process killed with SIGKILL while participants submit: every
answer the server confirmed is still there after a restart, and resending the one in flight
stores it once (runs without a browser)."""

from __future__ import annotations

import threading
import time

from study_web import StudyServer, Visitor, http, render_tiny_study

from gazebot.apps.study.folder import load_study

ANSWERS = {"q1": "2", "q2": "1", "q3": "2", "q4": "1", "q5": "1"}


def _post_all(
    browser: Visitor,
    link: str,
    pid: int,
    sessions: list[int],
    confirmed: list,
    killed: threading.Event,
):
    csrf = browser.form_token(link)
    for i, k in enumerate(sessions):
        if i == len(sessions) - 1:
            # The last answer waits for the kill: answers are certainly still unsent when it
            # comes, however late the main thread gets to it (others may be in flight).
            killed.wait(timeout=300)
        if killed.is_set():
            return
        try:
            data = {**ANSWERS, "csrf_token": csrf}
            status, _, _ = browser.request("POST", f"{link}/session/{k}", data)
        except OSError:  # the server died under this request
            return
        if status == 303:
            confirmed.append((pid, k))


def test_sigkill_while_submitting_loses_no_confirmed_answer(tmp_path):
    study_dir = tmp_path / "study"
    render_tiny_study(study_dir)
    study = load_study(study_dir)
    server = StudyServer(study_dir).start()
    killed = threading.Event()
    try:
        links = server.links
        browsers = {pid: Visitor(server.base) for pid in study.participants}
        csrf = {pid: browsers[pid].form_token(links[pid]) for pid in study.participants}
        for pid in study.participants:
            b, link, token = browsers[pid], links[pid], csrf[pid]
            consent = {"consent": "yes", "csrf_token": token}
            assert b.request("POST", f"{link}/consent", consent)[0] == 303
            assert b.request("POST", f"{link}/instructions", {"csrf_token": token})[0] == 303
        confirmed: list[tuple[int, int]] = []
        threads = [
            threading.Thread(
                target=_post_all,
                args=(
                    browsers[pid],
                    links[pid],
                    pid,
                    [0] + [s.session for s in study.sessions_of(pid)],
                    confirmed,
                    killed,
                ),
            )
            for pid in study.participants
        ]
        for t in threads:
            t.start()
        # Kill once some answers are confirmed, while the others are still being sent.
        deadline = time.monotonic() + 60
        while len(confirmed) < 8:
            assert time.monotonic() < deadline, "no answers confirmed within 60 s"
            time.sleep(0.001)
        server.kill()
        killed.set()
        for t in threads:
            t.join(timeout=30)
        at_kill = list(confirmed)
        assert len(at_kill) < len(study.participants) * 7  # mid-study: last answers wait

        server.start()
        assert server.links == links  # a link handed out stays valid across a restart
        stored = {(a.participant, a.session) for a in study.store().answers(include_practice=True)}
        assert set(at_kill) <= stored  # nothing confirmed is lost
        # Everyone carries on from where the server says they are; resent answers count once.
        for pid in study.participants:
            for k in [0] + [s.session for s in study.sessions_of(pid)]:
                data = {**ANSWERS, "csrf_token": csrf[pid]}  # a form loaded before the kill
                status, _, _ = browsers[pid].request("POST", f"{links[pid]}/session/{k}", data)
                assert status == 303
        answers = study.store().answers(include_practice=True)
        keys = [(a.participant, a.session) for a in answers]
        assert len(keys) == len(set(keys)) == len(study.participants) * 7
        status, _, body = http("GET", links[1])
        assert status == 200 and b"You have completed all 6 sessions" in body
    finally:
        killed.set()  # whatever failed, no thread is left waiting
        server.stop()
