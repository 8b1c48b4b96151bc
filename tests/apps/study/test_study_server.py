"""``gazebot study serve``: the participant's steps, stored answers, resume, double submits,
clear pages for bad ids, video range requests, the experimenter's pages, and ``study export``
feeding ``study analyze`` (through Flask's test client; the browser tests drive a real one)."""

from __future__ import annotations

import csv
import json
import re
import sqlite3

import numpy as np
import pytest
from study_responses import BEHAVIORS, responses_from_tables
from study_seed_tables import TABLE_6_1
from study_web import form_token, reach_start_time_of, render_tiny_study

from gazebot.apps.study.analysis import analyze, read_responses
from gazebot.apps.study.export import export_responses
from gazebot.apps.study.folder import load_study
from gazebot.apps.study.web.app import ADMIN_COOKIE, VISITOR_COOKIE, create_app
from gazebot.apps.study.web.security import new_token

ANSWERS = {"q1": "1", "q2": "2", "q3": "1", "q4": "1", "q5": "2"}


@pytest.fixture(scope="module")
def study_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("web") / "study"
    render_tiny_study(out)
    return out


@pytest.fixture
def fresh(study_dir, tmp_path):
    """A copy-free fresh start: the rendered folder with its answers file removed."""
    for suffix in ("", "-wal", "-shm"):
        (study_dir / f"responses.sqlite{suffix}").unlink(missing_ok=True)
    return study_dir


class Client:
    """Flask's test client used as a participant's browser would: ``/p/N...`` in a test stands
    for participant N's own link ``/p/TOKEN...``, it holds a visitor cookie (and with ``admin``
    signs in with the admin token), and every POST carries its form's CSRF token and the
    ``Origin`` a browser sends on the site's own forms."""

    def __init__(self, study_dir, remote="127.0.0.1", admin=False, **kw):
        self.app = create_app(str(study_dir), admin_token="admin-token-1234", **kw)
        self.web = self.app.extensions["gazebot_study"]
        self.c = self.app.test_client()
        self.c.environ_base["REMOTE_ADDR"] = remote
        self.c.environ_base["HTTP_ORIGIN"] = "http://localhost"
        self.c.set_cookie(VISITOR_COOKIE, new_token())  # as a browser that visited before
        if admin:
            self.sign_in()

    def sign_in(self, token="admin-token-1234"):
        """The experimenter's sign-in form, filled in as a browser would."""
        csrf = form_token(self.c.get("/admin").data)
        resp = self.c.post("/admin/login", data={"token": token, "csrf_token": csrf})
        assert resp.status_code == 303, resp.status_code
        return resp

    def url(self, path: str) -> str:
        m = re.fullmatch(r"/p/(\d+)(.*)", path)
        return self.web.link_path(int(m.group(1))) + m.group(2) if m else path

    def scope(self, path: str) -> str:
        return "p:" + self.url(path).split("/")[2] if path.startswith("/p/") else "admin"

    def csrf(self, path: str) -> str:
        """The CSRF token the form posting to ``path`` shows this browser."""
        scope = self.scope(path)
        if scope == "admin":
            cookie = self.c.get_cookie(ADMIN_COOKIE)
            return self.web.csrf(scope, cookie.value.split(".")[0]) if cookie else ""
        return self.web.csrf(scope, self.c.get_cookie(VISITOR_COOKIE).value)

    def get(self, path, **kw):
        return self.c.get(self.url(path), **kw)

    def post(self, path, data=None, **kw):
        data = {"csrf_token": self.csrf(path), **(data or {})}
        return self.c.post(self.url(path), data=data, **kw)


def client(study_dir, remote="127.0.0.1", **kw):
    return Client(study_dir, remote, **kw)


def start(c, pid=1):
    assert c.post(f"/p/{pid}/consent", data={"consent": "yes"}).status_code == 303
    assert c.post(f"/p/{pid}/instructions").status_code == 303


def test_participant_steps_in_order_consent_instructions_practice_sessions_done(fresh):
    c = client(fresh)
    page = c.get("/p/1")
    assert page.status_code == 200 and b"Consent" in page.data
    assert c.post("/p/1/consent", data={}).status_code == 400  # the box must be ticked
    resp = c.post("/p/1/consent", data={"consent": "yes"})
    assert resp.headers["Location"].endswith(c.url("/p/1"))
    page = c.get("/p/1").get_data(as_text=True)
    assert "Instructions" in page and "robot&#39;s head movement" in page  # the plan's head-only
    c.post("/p/1/instructions")
    assert "Practice session" in c.get("/p/1").get_data(as_text=True)
    assert c.post("/p/1/session/0", data=ANSWERS).status_code == 303
    n = len(load_study(fresh).sessions_of(1))
    for k in range(1, n + 1):
        page = c.get("/p/1").get_data(as_text=True)
        assert f"Session {k} of {n}" in page
        assert f'action="{c.url("/p/1")}/session/{k}"' in page
        assert c.post(f"/p/1/session/{k}", data={**ANSWERS, "comment": f"c{k}"}).status_code == 303
    page = c.get("/p/1")
    assert page.status_code == 200 and b"You have completed all 6 sessions" in page.data


def test_session_page_shows_the_seed_questions_and_no_behavior_names(fresh):
    c = client(fresh)
    start(c)
    page = c.get("/p/1").get_data(as_text=True)
    assert "Which handover did you like better? (1st or 2nd)" in page
    assert "wanted the giver to give the object? (1st or 2nd)" in page
    assert "Any other comments (optional)" in page
    for name in ("face", "hand", "short-face-hand", "jaco2", "sawyer", '.mp4">'):
        assert f"{name}_" not in page and f"/{name}" not in page
    assert page.count("<video") == 2 and "disabled" in page  # questions wait for both videos


def test_missing_answer_is_refused_with_the_question_named_and_nothing_stored(fresh):
    c = client(fresh)
    start(c)
    resp = c.post("/p/1/session/0", data={k: v for k, v in ANSWERS.items() if k != "q3"})
    assert resp.status_code == 400
    assert b"Question 3 (Which handover seemed more natural? (1st or 2nd)) needs" in resp.data
    assert b'value="1" id="q1-1" required checked' in resp.data  # the given answers are kept
    assert load_study(fresh).store().progress(1).answered == ()


def test_double_submit_records_once_and_first_answers_win(fresh):
    c = client(fresh)
    start(c)
    c.post("/p/1/session/0", data=ANSWERS)
    first = c.post("/p/1/session/1", data=ANSWERS)
    again = c.post("/p/1/session/1", data={**ANSWERS, "q1": "2"})
    assert first.status_code == again.status_code == 303
    rows = load_study(fresh).store().answers()
    assert [(a.session, a.answers["q1"]) for a in rows] == [(1, 1)]
    assert "Session 2 of 6" in c.get("/p/1").get_data(as_text=True)


def test_a_future_session_cannot_be_answered_out_of_order(fresh):
    c = client(fresh)
    start(c)
    resp = c.post("/p/1/session/3", data=ANSWERS)
    assert resp.status_code == 409 and b"not your current step" in resp.data
    assert load_study(fresh).store().progress(1).answered == ()


def test_a_new_app_on_the_same_folder_resumes_where_the_participant_was(fresh):
    c = client(fresh)
    start(c)
    for k in (0, 1, 2):
        c.post(f"/p/1/session/{k}", data=ANSWERS)
    resumed = client(fresh)  # a restarted server: nothing kept in memory
    assert "Session 3 of 6" in resumed.get("/p/1").get_data(as_text=True)


@pytest.mark.parametrize(
    "path", ["/p/99", "/p/0", "/p/abc", "/p/-1", "/p/AAAAAAAAAAAAAAAAAAAAAAAA", "/nowhere"]
)
def test_unknown_participant_link_or_page_gets_a_clear_page_not_a_traceback(fresh, path):
    resp = client(fresh).c.get(path)  # the path as typed, not a participant's link
    assert resp.status_code == 404
    text = resp.get_data(as_text=True)
    assert "Traceback" not in text
    if path.startswith("/p/"):
        assert "No such participant link: check the link you were given." in text
    else:
        assert "no such page" in text


def test_participant_links_are_random_tokens_not_their_numbers(fresh):
    c = client(fresh)
    links = c.web.links
    assert sorted(links) == load_study(fresh).participants
    assert len(set(links.values())) == len(links)
    for p, token in links.items():
        assert re.fullmatch(r"[A-Za-z0-9_-]{24}", token) and str(p) != token
    # Participant 1's page by number does not open, and its forms refuse another's token.
    assert c.c.get("/p/1").status_code == 404
    other = {"consent": "yes", "csrf_token": c.csrf("/p/2")}
    assert c.c.post(c.url("/p/1") + "/consent", data=other).status_code == 403
    assert load_study(fresh).store().progress(1).mode is None
    # A restarted server keeps the links handed out.
    assert client(fresh).web.links == links


def test_index_sends_a_participant_code_to_their_page(fresh):
    c = client(fresh)
    token = c.web.links[2]
    assert c.get(f"/?participant={token}").headers["Location"].endswith(f"/p/{token}")
    assert c.get("/?participant=x1").status_code == 400
    # A digit that is not ASCII (int() would take "²" apart) is a clear 400, not a 500.
    for code in ("²", "١٢", "3²", "%00", " "):
        resp = c.get("/", query_string={"participant": code})
        assert resp.status_code in (200, 400), code
        assert b"Something went wrong" not in resp.data
    assert c.get("/", query_string={"participant": "²"}).status_code == 400


def test_videos_are_served_with_range_requests_and_without_their_file_name(fresh):
    c = client(fresh)
    full = c.get("/p/1/video/1/1.mp4")
    assert full.status_code == 200 and full.headers["Accept-Ranges"] == "bytes"
    part = c.get("/p/1/video/1/1.mp4", headers={"Range": "bytes=10-49"})
    assert part.status_code == 206
    assert part.headers["Content-Range"] == f"bytes 10-49/{len(full.data)}"
    assert part.data == full.data[10:50]
    assert "Content-Disposition" not in part.headers  # the file name names the behavior
    assert full.data == load_study(fresh).video_path(1, 1, 1).read_bytes()
    assert c.get("/p/1/video/1/3.mp4").status_code == 404
    assert c.get("/p/1/video/99/1.mp4").status_code == 404


@pytest.mark.parametrize("remote", ["192.0.2.7", "127.0.0.1", "127.0.1.1"])
def test_admin_needs_the_token_signed_in_by_a_form_not_a_url(fresh, remote):
    """From anywhere, loopback included (on Debian a browser on the machine opening its own
    name comes from 127.0.1.1), unless ``local_admin`` is asked for."""
    remote = client(fresh, remote=remote)
    page = remote.get("/admin")
    assert page.status_code == 403 and b'action="/admin/login"' in page.data
    # A token in the URL (which logs and browser histories keep) opens nothing.
    assert remote.get("/admin?token=admin-token-1234").status_code == 403
    login_csrf = form_token(page.data)
    bad = remote.c.post("/admin/login", data={"token": "bad", "csrf_token": login_csrf})
    assert bad.status_code == 403 and b"not the admin token" in bad.data
    resp = remote.sign_in()
    assert resp.headers["Location"].endswith("/admin")
    cookie = resp.headers["Set-Cookie"]
    assert "admin-token-1234" not in cookie and "HttpOnly" in cookie and "SameSite=Strict" in cookie
    assert remote.get("/admin").status_code == 200  # the sign-in is kept in a cookie


def test_admin_page_lists_each_participants_link(fresh):
    c = client(fresh, admin=True)
    page = c.get("/admin").get_data(as_text=True)
    for token in c.web.links.values():
        assert f"http://localhost/p/{token}</code>" in page


def test_admin_shows_each_participants_progress(fresh):
    c = client(fresh, admin=True)
    start(c, 2)
    c.post("/p/2/session/0", data=ANSWERS)
    c.post("/p/2/session/1", data=ANSWERS)
    page = c.get("/admin").get_data(as_text=True)
    assert "1 of 6 participants started, 0 finished" in page
    assert "<td>2</td><td>video</td><td>1 / 6</td><td>session 2</td>" in page


def test_in_person_mode_enters_answers_in_plan_order_with_the_in_person_question_5(fresh):
    study = load_study(fresh)
    c = client(fresh, admin=True)
    sessions = study.sessions_of(3)
    for s in sessions:
        page = c.get("/admin/in-person/3").get_data(as_text=True)
        order = f"Handover 1: <strong>{s.first}</strong>, then handover 2: <strong>{s.second}"
        assert order in page
        assert "the robot wanted you to give the object? (1st or 2nd)" in page
        resp = c.post("/admin/in-person/3", data={**ANSWERS, "session": str(s.session)})
        assert resp.status_code == 303
    assert "All sessions entered." in c.get("/admin/in-person/3").get_data(as_text=True)
    # The participant's own page says the experimenter enters the answers.
    assert client(fresh).get("/p/3").status_code == 409
    answers = study.store().answers()
    assert [a.session for a in answers] == [s.session for s in sessions]
    assert {a.mode for a in answers} == {"in-person"}
    assert study.store().progress(3).finished_at is not None


def test_admin_table_shows_an_in_person_participants_next_live_pair_not_a_practice(fresh):
    """In person there is no practice session: after two entered pairs the table says session
    3 (it said "practice" for as long as the participant took part)."""
    study = load_study(fresh)
    c = client(fresh, admin=True)
    for s in study.sessions_of(3)[:2]:
        resp = c.post("/admin/in-person/3", data={**ANSWERS, "session": str(s.session)})
        assert resp.status_code == 303
    row = "<td>3</td><td>in-person</td><td>2 / 6</td><td>session 3</td>"
    assert row in c.get("/admin").get_data(as_text=True)


def test_in_person_entry_for_an_online_participant_is_refused(fresh):
    c = client(fresh, admin=True)
    start(c, 4)
    resp = c.post("/admin/in-person/4", data={**ANSWERS, "session": "1"})
    assert resp.status_code == 409 and b"answers online" in resp.data


def test_export_writes_what_analyze_reads_with_timestamps_and_time_per_session(fresh, tmp_path):
    c = client(fresh)
    for pid in (1, 2):
        start(c, pid)
        for k in range(0, 7):
            c.get(f"/p/{pid}")  # the session page is shown: its time starts
            c.post(f"/p/{pid}/session/{k}", data={**ANSWERS, "q2": str(1 + (k + pid) % 2)})
    out, n = export_responses(fresh, tmp_path / "responses.csv")
    assert n == 12  # the practice is left out
    with out.open() as fh:
        rows = list(csv.DictReader(fh))
    assert rows[0]["shown_at"] <= rows[0]["submitted_at"] and rows[0]["submitted_at"].endswith(
        "+00:00"
    )
    assert all(float(r["seconds"]) >= 0 for r in rows)
    assert {r["gaze_mode"] for r in rows} == {"head-only"} and {r["group"] for r in rows} == {""}
    plan = {(s.participant, s.session): s for s in load_study(fresh).plan}
    for r in rows:
        s = plan[(int(r["participant"]), int(r["session"]))]
        assert (r["first"], r["second"]) == (s.first, s.second)
        assert r["q2"] == str(1 + (int(r["session"]) + int(r["participant"])) % 2)
        # The seed's reach-start time of both handovers the session showed.
        for k in ("first", "second"):
            assert float(r[f"{k}_reach_start_time"]) == reach_start_time_of(r[k])
    result = analyze(read_responses(out))
    assert result.per_level[""]["likability"].participants == 2


def test_export_of_a_study_without_answers_says_so(fresh, tmp_path):
    with pytest.raises(ValueError, match="no answers yet"):
        export_responses(fresh, tmp_path / "r.csv")


def test_store_commits_each_answer_in_wal_mode(fresh):
    c = client(fresh)
    start(c)
    c.post("/p/1/session/0", data=ANSWERS)
    con = sqlite3.connect(fresh / "responses.sqlite")
    assert con.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    assert con.execute("SELECT count(*) FROM answers").fetchone()[0] == 1
    con.close()


def test_table_6_1_reproduced_through_the_served_6_3_study(tmp_path):
    """The seed's 6.3 video study as run: four behaviors, no condition, 24 participants, 12
    sessions each; the answers behind Table 6.1 entered through the web pages, exported and
    analyzed give the table's P_i."""
    out = tmp_path / "study"
    render_tiny_study(out, behaviors=BEHAVIORS, participants=24)
    table_rows = responses_from_tables({"": TABLE_6_1})
    answer_of = {(r["participant"], r["first"], r["second"]): r for r in table_rows}
    study = load_study(out)
    c = client(out)
    for pid in study.participants:
        start(c, pid)
        c.post(f"/p/{pid}/session/0", data=ANSWERS)
        for s in study.sessions_of(pid):
            r = answer_of[(pid, s.first, s.second)]
            data = {q: str(r[q]) for q in ANSWERS}
            assert c.post(f"/p/{pid}/session/{s.session}", data=data).status_code == 303
    csv_path, n = export_responses(out, tmp_path / "responses.csv")
    assert n == 24 * 12
    result = analyze(read_responses(csv_path), behaviors=BEHAVIORS)
    for measure, data in TABLE_6_1.items():
        r = result.per_level[""][measure]
        np.testing.assert_allclose(r.wins, data["wins"])
        assert np.round(r.fit.p, 2).tolist() == pytest.approx(data["P"], abs=1e-9)
        assert r.chi2.p_value < 1e-4  # "all of the chi2 values are large (p < 0.0001)"
    json.dumps(result.to_json())


def test_local_admin_opens_admin_to_loopback_only_when_asked_for(fresh):
    assert client(fresh).get("/admin").status_code == 403  # the default
    c = client(fresh, local_admin=True)
    assert c.get("/admin").status_code == 200
    # Its forms work with a session of its own (a cookie), as a signed-in one's do.
    start(client(fresh), 5)
    resp = c.post("/admin/in-person/5", data={**ANSWERS, "session": "1"})
    assert resp.status_code == 409 and b"answers online" in resp.data
    assert client(fresh, remote="192.0.2.7", local_admin=True).get("/admin").status_code == 403


def test_export_names_the_mode_as_group_when_a_study_has_both(fresh, tmp_path):
    c = client(fresh, admin=True)
    start(c, 1)
    c.post("/p/1/session/0", data=ANSWERS)
    c.post("/p/1/session/1", data=ANSWERS)
    first = load_study(fresh).sessions_of(3)[0]
    c.get("/admin/in-person/3")  # the experimenter's page for the live pair
    c.post("/admin/in-person/3", data={**ANSWERS, "session": str(first.session)})
    out, n = export_responses(fresh, tmp_path / "r.csv")
    with out.open() as fh:
        rows = {r["participant"]: r for r in csv.DictReader(fh)}
    assert n == 2
    assert (rows["1"]["group"], rows["1"]["mode"]) == ("video", "video")
    assert rows["3"]["group"] == "in-person" and float(rows["3"]["seconds"]) >= 0
    assert {r.group for r in read_responses(out)} == {"video", "in-person"}


def test_export_and_analyze_commands_on_a_served_study(fresh, tmp_path, capsys):
    import argparse

    from gazebot.apps.cli import study as study_cli

    def run(argv):
        parser = argparse.ArgumentParser(prog="gazebot")
        study_cli.register(parser.add_subparsers(dest="command"))
        args = parser.parse_args(argv)
        return args.func(args)

    c = client(fresh)
    for pid in (1, 2):
        start(c, pid)
        for k in range(0, 7):
            c.post(f"/p/{pid}/session/{k}", data={**ANSWERS, "q1": str(1 + (k + pid) % 2)})
    out = tmp_path / "responses.csv"
    assert run(["study", "export", str(fresh), "--out", str(out)]) == 0
    assert "wrote 12 answered sessions" in capsys.readouterr().out
    assert run(["study", "analyze", str(out), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["per_level"][""]["likability"]["participants"] == 2
    assert set(doc["bias_per_question"]) == {"q1", "q2", "q3", "q4", "q5"}


def test_the_study_folders_consent_text_replaces_the_default(fresh):
    (fresh / "consent.txt").write_text("Approved text, part one.\n\nPart <two>.\n")
    try:
        page = client(fresh).get("/p/5").get_data(as_text=True)
    finally:
        (fresh / "consent.txt").unlink()
    assert "<p>Approved text, part one.</p>" in page and "<p>Part &lt;two&gt;.</p>" in page
    assert "You are invited" not in page
    assert "You are invited" in client(fresh).get("/p/5").get_data(as_text=True)


def test_serve_on_all_interfaces_prints_an_address_a_browser_can_open():
    import socket

    from gazebot.apps.study.web.server import base_url

    assert base_url("0.0.0.0", 8000) == f"http://{socket.gethostname()}:8000"
    assert base_url("::", 80).startswith(f"http://{socket.gethostname()}")
    assert base_url("127.0.0.1", 8000) == "http://127.0.0.1:8000"
    assert base_url("::1", 8000) == "http://[::1]:8000"


def test_in_person_familiarity_and_measured_reach_starts_reach_the_export_and_the_anova(
    fresh, tmp_path
):
    """The experimenter enters the familiarity answer with the first live pair and the measured
    reach-start times with each pair; the export carries them (not the videos' times) and
    ``study in-person``'s ANOVA and familiarity summary read them back."""
    from scipy import stats

    from gazebot.apps.study.in_person import (
        FAMILIARITY_QUESTION,
        familiarity_summary,
        reach_start_anova,
        read_in_person,
    )

    study = load_study(fresh)
    c = client(fresh, admin=True)
    fam = {3: 1, 4: 2, 5: 2}
    sent: dict[str, list[float]] = {}
    for p, answer in fam.items():
        for i, s in enumerate(study.sessions_of(p)):
            page = c.get(f"/admin/in-person/{p}").get_data(as_text=True)
            assert (FAMILIARITY_QUESTION in page) == (i == 0)  # asked once
            t1, t2 = round(0.1 * p + 0.01 * i, 3), round(-0.25 + 0.03 * i, 3)
            data = {**ANSWERS, "session": str(s.session), "first_reach_start_time": str(t1),
                    "second_reach_start_time": str(t2)}
            if i == 0:
                data["familiarity"] = str(answer)
            assert c.post(f"/admin/in-person/{p}", data=data).status_code == 303
            sent.setdefault(s.first, []).append(t1)
            sent.setdefault(s.second, []).append(t2)
    out, _ = export_responses(fresh, tmp_path / "r.csv")
    data = read_in_person(out)
    assert data.familiarity == {("", "3"): 1, ("", "4"): 2, ("", "5"): 2}
    assert {k: sorted(v) for k, v in data.reach_start.items()} == {
        k: sorted(v) for k, v in sent.items()
    }
    # Not the rendered videos' reach-start times: the measured ones.
    assert reach_start_time_of("face") not in data.reach_start["face"]
    anova = reach_start_anova(data.reach_start)
    expected = stats.f_oneway(*(sent[k] for k in sorted(sent)))
    assert (anova.f, anova.p) == pytest.approx((expected.statistic, expected.pvalue))
    summary = familiarity_summary(data.familiarity)
    assert (summary.mean, summary.sd) == pytest.approx((5 / 3, np.sqrt(1 / 3)))


def test_in_person_entry_refuses_a_reach_start_that_is_not_seconds(fresh):
    study = load_study(fresh)
    c = client(fresh, admin=True)
    s = study.sessions_of(3)[0]
    resp = c.post("/admin/in-person/3", data={**ANSWERS, "session": str(s.session),
                                               "first_reach_start_time": "soon"})
    assert resp.status_code == 400 and b"Reach-start time of handover 1" in resp.data
    resp = c.post("/admin/in-person/3", data={**ANSWERS, "session": str(s.session),
                                               "familiarity": "9"})
    assert resp.status_code == 400 and b"Familiarity must be 1-5" in resp.data
    assert study.store().answers() == []
