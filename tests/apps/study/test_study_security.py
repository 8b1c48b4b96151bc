"""The study server as an attacker or a careless user meets it: relative study folders, links
only their participant can use, CSRF tokens bound to a random cookie and an origin check on
every POST, the ``Host`` checked (DNS rebinding), no admin without the token, bodies capped
before they are read, security headers, the admin token kept out of URLs and ``ps``, and a
log flood rate-limited."""

from __future__ import annotations

import csv
import logging
import os
import socket
import stat

import pytest
from study_web import StudyServer, Visitor, form_token, http, render_tiny_study

from gazebot.apps.study.web.app import ADMIN_COOKIE, VISITOR_COOKIE, create_app
from gazebot.apps.study.web.security import (
    MAX_BODY_BYTES,
    RateLimitFilter,
    cross_site_reason,
    rate_limit_logs,
)
from gazebot.apps.study.web.server import ADMIN_TOKEN_FILE, admin_token_source, served_host_names

ADMIN_TOKEN = "admin-token-1234"
ANSWERS = {"q1": "1", "q2": "2", "q3": "1", "q4": "1", "q5": "2"}


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    out = tmp_path_factory.mktemp("sec") / "study"
    render_tiny_study(out)
    return out


@pytest.fixture
def study_dir(rendered):
    """The rendered study without answers: each test starts with no participant locked."""
    for suffix in ("", "-wal", "-shm"):
        (rendered / f"responses.sqlite{suffix}").unlink(missing_ok=True)
    return rendered


def _client(study_dir, remote="127.0.0.1", **kw):
    """(the app's study, a test client from ``remote``); a POST without its own ``Origin``
    header carries the one a browser sends on the site's own forms."""
    app = create_app(str(study_dir), admin_token=ADMIN_TOKEN, **kw)
    c = app.test_client()
    c.environ_base["REMOTE_ADDR"] = remote
    return app.extensions["gazebot_study"], c


SAME_ORIGIN = {"Origin": "http://localhost"}


def _sign_in(c) -> str:
    """Sign ``c`` in with the admin token as the experimenter's browser does; returns the CSRF
    token of the experimenter's forms, read from the in-person page."""
    page = c.get("/admin")
    data = {"token": ADMIN_TOKEN, "csrf_token": form_token(page.data)}
    assert c.post("/admin/login", data=data, headers=SAME_ORIGIN).status_code == 303
    return form_token(c.get("/admin/in-person/6").data)


def test_a_relative_study_folder_serves_its_videos(study_dir, monkeypatch):
    """``gazebot study serve study/`` from the folder above: Flask's send_file would resolve a
    relative path against gazebot's package, answering 500 for every video."""
    monkeypatch.chdir(study_dir.parent)
    web, c = _client("study")
    link = web.link_path(1)
    resp = c.get(f"{link}/video/0/1.mp4")
    assert resp.status_code == 200
    assert resp.data == web.study.video_path(1, 0, 1).read_bytes()
    assert web.study.root.is_absolute()


def test_every_post_needs_its_forms_csrf_token(study_dir):
    web, c = _client(study_dir)
    link = web.link_path(3)
    page = c.get(link).get_data(as_text=True)
    visitor = c.get_cookie(VISITOR_COOKIE).value
    no_token = c.post(f"{link}/consent", data={"consent": "yes"}, headers=SAME_ORIGIN)
    assert no_token.status_code == 403
    # Another participant's form's token, or this link's for another scope, opens nothing.
    for scope in ("p:" + web.links[2], "login", "admin"):
        bad = {"consent": "yes", "csrf_token": web.csrf(scope, visitor)}
        assert c.post(f"{link}/consent", data=bad, headers=SAME_ORIGIN).status_code == 403
    assert web.store.progress(3).mode is None
    good = {"consent": "yes", "csrf_token": form_token(page)}
    assert c.post(f"{link}/consent", data=good, headers=SAME_ORIGIN).status_code == 303
    # The experimenter's forms too: a cross-site form cannot lock a participant out.
    resp = c.post("/admin/in-person/4", data={"session": "1"}, headers=SAME_ORIGIN)
    assert resp.status_code == 403
    assert web.store.progress(4).mode is None


@pytest.mark.parametrize(
    ("headers", "allowed"),
    [
        ({"Origin": "http://evil.example"}, False),
        ({"Origin": "http://localhost.evil.example"}, False),
        ({"Origin": "http://localhost:8000"}, False),  # another port: another origin
        ({"Origin": "null", "Sec-Fetch-Site": "cross-site"}, False),
        # A no-referrer page of another site posting to a plain-HTTP LAN host: browsers send
        # Sec-Fetch-* to secure origins only, so it comes with Origin: null and nothing else.
        ({"Origin": "null"}, False),
        ({"Origin": "null", "Referer": "http://localhost/admin"}, False),  # a Referer is no proof
        ({"Sec-Fetch-Site": "same-site"}, False),
        ({"Referer": "http://evil.example/page"}, False),
        ({}, False),  # names no origin at all
        ({"Origin": "http://localhost"}, True),
        ({"Origin": "HTTP://LOCALHOST"}, True),
        ({"Origin": "null", "Sec-Fetch-Site": "same-origin"}, True),
        ({"Sec-Fetch-Site": "same-origin"}, True),
        ({"Referer": "http://localhost/admin/in-person/5"}, True),  # an old browser
    ],
)
def test_a_post_from_another_site_is_refused_even_with_a_valid_token(study_dir, headers, allowed):
    web, c = _client(study_dir)
    csrf = _sign_in(c)
    data = {"session": "1", "csrf_token": csrf}
    resp = c.post("/admin/in-person/5", data=data, headers=headers)
    assert (resp.status_code != 403) == allowed, resp.status_code
    if not allowed:
        assert b"may not post here" in resp.data or b"may not post" in resp.data
        assert web.store.progress(5).mode is None


def test_origin_check_is_the_same_for_the_servers_own_host_and_port():
    host = "study.lab.example:8000"
    assert cross_site_reason({"Origin": "http://study.lab.example:8000"}, host) is None
    assert cross_site_reason({"Referer": "http://study.lab.example:8000/p/x"}, host) is None
    assert cross_site_reason({"Origin": "http://study.lab.example"}, host) is not None
    assert cross_site_reason({"Origin": "http://[::1"}, host) is not None  # malformed


# ---- the review's attacks, each reproduced (each answered 200/303 before the fix) ----


def test_an_admin_csrf_token_taken_from_the_login_page_opens_nothing(study_dir):
    """The sign-in page is public: its token is the visitor's own, bound to the visitor's
    cookie and only good for signing in, never an experimenter's form token."""
    web, victim = _client(study_dir, remote="192.0.2.10")
    victim_csrf = _sign_in(victim)
    _, attacker = _client(study_dir, remote="192.0.2.66")
    stolen = form_token(attacker.get("/admin").data)
    assert stolen != victim_csrf
    data = {**ANSWERS, "session": "1", "csrf_token": stolen}
    for c in (victim, attacker):
        resp = c.post("/admin/in-person/4", data=data, headers=SAME_ORIGIN)
        assert resp.status_code == 403
    assert web.store.progress(4).mode is None
    # The victim's own page token works (the check refuses the stolen token, not the form).
    data["csrf_token"] = victim_csrf
    resp = victim.post("/admin/in-person/4", data=data, headers=SAME_ORIGIN)
    assert resp.status_code == 303 and web.store.progress(4).mode == "in-person"


def test_origin_null_from_127_0_1_1_does_not_lock_a_participant_out(study_dir):
    """The review's chain: the experimenter's browser on the serving machine opens the printed
    http://HOSTNAME:8000 (127.0.1.1 on Debian); a no-referrer page of another site posts a
    form to /admin/in-person/4 with the token of the public sign-in page: Origin: null, no
    Sec-Fetch-Site (plain HTTP). Refused by the origin check, by the missing admin session
    (no loopback admin by default), and by the token."""
    _, attacker = _client(study_dir, remote="192.0.2.66")
    stolen = form_token(attacker.get("/admin").data)  # the public sign-in page
    web, browser = _client(study_dir, remote="127.0.1.1")
    data = {**ANSWERS, "session": "1", "csrf_token": stolen}
    resp = browser.post("/admin/in-person/4", data=data, headers={"Origin": "null"})
    assert resp.status_code == 403
    # Even with the experimenter signed in, and with loopback admin asked for.
    for kw in ({}, {"local_admin": True}):
        web, browser = _client(study_dir, remote="127.0.1.1", **kw)
        own = form_token(browser.get("/admin/in-person/6").data) if kw else _sign_in(browser)
        for headers in ({"Origin": "null"}, SAME_ORIGIN):
            resp = browser.post("/admin/in-person/4", data=data, headers=headers)
            assert resp.status_code == 403
        # The page's own token from an unnamed origin: the origin check alone refuses it.
        resp = browser.post(
            "/admin/in-person/4", data={**data, "csrf_token": own}, headers={"Origin": "null"}
        )
        assert resp.status_code == 403 and b"Origin: null" in resp.data
    assert web.store.progress(4).mode is None


@pytest.mark.parametrize("remote", ["127.0.0.1", "127.0.1.1", "::1"])
def test_loopback_without_the_token_is_no_admin(study_dir, remote):
    web, c = _client(study_dir, remote=remote)
    page = c.get("/admin")
    assert page.status_code == 403 and b'action="/admin/login"' in page.data
    assert web.links[1].encode() not in page.data
    assert c.get("/admin/in-person/2").status_code == 403


@pytest.mark.parametrize("path", ["/admin", "/", "/healthz"])
def test_a_forged_host_gets_400_dns_rebinding(study_dir, path):
    """A page of evil.example rebound to 127.0.0.1 reads the answers it gets: none, even where
    loopback admin is on."""
    web, c = _client(study_dir, local_admin=True)
    resp = c.get(path, headers={"Host": "evil.example:8000"})
    assert resp.status_code == 400 and b"--allowed-host" in resp.data
    assert not any(t.encode() in resp.data for t in web.links.values())
    link = web.link_path(1)
    assert c.get(link, headers={"Host": "evil.example"}).status_code == 400
    resp = c.post(f"{link}/consent", data={"consent": "yes"}, headers={"Host": "evil.example"})
    assert resp.status_code == 400 and web.store.progress(1).mode is None


@pytest.mark.parametrize(
    ("host", "ok"),
    [
        ("localhost", True),
        ("LOCALHOST:8000", True),
        ("127.0.0.1:8000", True),
        ("[::1]:8000", True),
        ("192.168.1.20:8000", True),  # an IP address: no rebinding possible
        ("study.lab.example:8000", True),  # given with allowed_hosts
        ("evil.example", False),
        ("localhost.evil.example", False),
        ("127.0.0.1.nip.io", False),
        ("localhost:notaport", False),
        ("", False),
    ],
)
def test_host_names_the_server_answers_to(study_dir, host, ok):
    allowed = ("localhost", "127.0.0.1", "::1", "study.lab.example")
    _, c = _client(study_dir, local_admin=True, allowed_hosts=allowed)
    resp = c.get("/admin", headers={"Host": host})
    assert (resp.status_code == 200) == ok, resp.status_code
    assert ok or resp.status_code == 400


def test_served_host_names_for_a_bound_address_and_the_wildcard():
    assert served_host_names("127.0.0.1") == ("localhost", "127.0.0.1", "::1")
    assert "study.lab.example" in served_host_names("127.0.0.1", ("Study.Lab.Example",))
    everywhere = served_host_names("0.0.0.0")
    assert socket.gethostname().lower() in everywhere and "localhost" in everywhere
    assert "192.168.1.5" in served_host_names("192.168.1.5")


def test_csrf_tokens_are_random_per_visitor_and_per_admin_session(study_dir):
    """Not derivable from anything public: two browsers on one link get different tokens, and
    one browser's token does not work with another's cookie."""
    web, a = _client(study_dir)
    _, b = _client(study_dir)
    link = web.link_path(2)
    token_a, token_b = form_token(a.get(link).data), form_token(b.get(link).data)
    assert token_a != token_b
    cookie = a.get_cookie(VISITOR_COOKIE)
    assert cookie.http_only and cookie.same_site == "Lax"
    resp = b.post(
        f"{link}/consent", data={"consent": "yes", "csrf_token": token_a}, headers=SAME_ORIGIN
    )
    assert resp.status_code == 403 and web.store.progress(2).mode is None
    # The experimenter: a new random session at each sign-in, each with its own token.
    first = _sign_in(a)
    sid = a.get_cookie(ADMIN_COOKIE).value
    second = _sign_in(b)
    assert first != second and b.get_cookie(ADMIN_COOKIE).value != sid
    assert a.get_cookie(ADMIN_COOKIE).same_site == "Strict"
    data = {**ANSWERS, "session": "1", "csrf_token": first}
    assert b.post("/admin/in-person/4", data=data, headers=SAME_ORIGIN).status_code == 403
    assert web.store.progress(4).mode is None
    # A forged admin cookie (a session id without the server's MAC) is no sign-in.
    _, c = _client(study_dir, remote="192.0.2.7")
    c.set_cookie(ADMIN_COOKIE, sid.split(".")[0] + ".forged")
    assert c.get("/admin").status_code == 403


class _Clock:
    """A Unix clock moved by hand."""

    def __init__(self, now: float) -> None:
        self.now = now

    def __call__(self) -> float:
        return self.now


def test_an_admin_sign_in_expires_and_asks_for_the_token_again(study_dir):
    clock = _Clock(1_800_000_000.0)
    _, c = _client(study_dir, remote="192.0.2.7", admin_session_s=3600, clock=clock)
    _sign_in(c)
    cookie = c.get_cookie(ADMIN_COOKIE)
    assert cookie.max_age == 3600
    clock.now += 3599
    assert c.get("/admin").status_code == 200
    clock.now += 2  # one hour and a second after the sign-in
    assert c.get("/admin").status_code == 403
    # A cookie whose time was edited by hand is no sign-in either (the MAC covers the time).
    sid, issued, mac = cookie.value.split(".")
    c.set_cookie(ADMIN_COOKIE, f"{sid}.{int(clock.now)}.{mac}")
    assert c.get("/admin").status_code == 403
    _sign_in(c)  # signing in again opens it
    assert c.get("/admin").status_code == 200
    # A time that is not ASCII digits (a raw 0xB2 byte arrives as '²') is no sign-in, not a 500.
    c.set_cookie(ADMIN_COOKIE, f"{sid}.\u00b2.{mac}")
    assert c.get("/admin").status_code == 403


def test_a_body_over_the_cap_is_refused_with_413(study_dir):
    web, c = _client(study_dir)
    link = web.link_path(2)
    big = {"comment": "x" * (MAX_BODY_BYTES + 1), "csrf_token": form_token(c.get(link).data)}
    resp = c.post(f"{link}/session/0", data=big, headers=SAME_ORIGIN)
    assert resp.status_code == 413 and b"Too large" in resp.data
    assert web.store.progress(2).answered == ()


def test_every_response_has_the_security_headers(study_dir):
    web, c = _client(study_dir)
    for path in ("/", web.link_path(1), "/admin", "/nowhere", f"{web.link_path(1)}/video/0/1.mp4"):
        h = c.get(path).headers
        csp = h["Content-Security-Policy"]
        assert "frame-ancestors 'none'" in csp and "default-src 'none'" in csp
        assert "'unsafe-inline'" not in csp
        # same-origin: the site's own forms carry their origin; other sites learn no link.
        assert h["Referrer-Policy"] == "same-origin"
        assert h["X-Content-Type-Options"] == "nosniff"
    # The page's own script and style carry this response's nonce.
    resp = c.get("/")
    nonce = resp.headers["Content-Security-Policy"].split("'nonce-")[1].split("'")[0]
    assert f'<style nonce="{nonce}">' in resp.get_data(as_text=True)
    assert nonce not in c.get("/").headers["Content-Security-Policy"]  # fresh per response


def test_admin_token_comes_from_a_file_or_the_environment_never_the_command_line(tmp_path):
    f = tmp_path / "token"
    f.write_text("from-a-file-0123\n")
    assert admin_token_source(tmp_path, f, {}) == ("from-a-file-0123", str(f))
    env = {"GAZEBOT_STUDY_ADMIN_TOKEN": "from-the-env-0123"}
    assert admin_token_source(tmp_path, None, env)[0] == "from-the-env-0123"
    token, where = admin_token_source(tmp_path, None, {})
    written = tmp_path / ADMIN_TOKEN_FILE
    assert where == str(written) and written.read_text().strip() == token and len(token) >= 20
    assert stat.S_IMODE(written.stat().st_mode) == 0o600
    f.write_text("short\n")
    with pytest.raises(ValueError, match="at least 12 characters"):
        admin_token_source(tmp_path, f, {})


def test_log_flood_is_rate_limited_with_a_count_of_what_was_dropped():
    now = [0.0]
    flt = RateLimitFilter(interval_s=10.0, clock=lambda: now[0])
    logger = logging.getLogger("gazebot.test.flood")
    logger.propagate = False
    seen: list[str] = []
    handler = logging.Handler()
    handler.emit = lambda r: seen.append(r.getMessage())
    logger.addHandler(handler)
    logger.addFilter(flt)
    try:
        for i in range(12_000):
            now[0] = i * 0.015  # 12,000 lines in 3 minutes, as waitress logged them
            logger.warning("Task queue depth is %d", i % 7)
        logger.warning("another message")
    finally:
        logger.removeHandler(handler)
        logger.removeFilter(flt)
    assert len(seen) == 19  # one per 10 s of 180 s, and the other message
    assert "more like this" in seen[1] and seen[-1] == "another message"
    installed = rate_limit_logs()
    assert installed in logging.getLogger("waitress.queue").filters


def test_real_server_on_a_relative_folder_writes_links_and_refuses_a_huge_body_unread(tmp_path):
    render_tiny_study(tmp_path / "study")
    server = StudyServer("study", cwd=tmp_path).start()  # relative, as the README shows
    try:
        with (tmp_path / "study" / "participant-links.csv").open(newline="") as fh:
            rows = list(csv.DictReader(fh))
        assert list(rows[0]) == ["participant", "url"] and len(rows) == 6
        link = server.links[1]
        assert link.startswith(f"{server.base}/p/") and not link.endswith("/p/1")
        status, _, body = http("GET", f"{link}/video/0/1.mp4")
        assert status == 200 and len(body) > 0
        # Through waitress too: a rebound name gets 400, a browser's own form goes through.
        status, _, body = http("GET", f"{server.base}/admin", headers={"Host": "evil.example"})
        assert status == 400 and link.encode() not in body
        browser = Visitor(server.base)
        consent = {"consent": "yes", "csrf_token": browser.form_token(link)}
        assert browser.request("POST", f"{link}/consent", consent)[0] == 303
        consent["csrf_token"] = Visitor(server.base).form_token(link)  # another browser's
        assert browser.request("POST", f"{link}/consent", consent)[0] == 403
        # 900 MB announced, none sent: waitress answers 413 from the header alone.
        path = link.split(str(server.port), 1)[1]
        with socket.create_connection(("127.0.0.1", server.port), timeout=30) as s:
            s.sendall(
                f"POST {path}/session/0 HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                "Content-Type: application/x-www-form-urlencoded\r\n"
                "Content-Length: 900000000\r\n\r\n".encode()
            )
            reply = s.recv(4096).decode(errors="replace")
        assert reply.startswith("HTTP/1.1 413"), reply[:200]
        # Chunked, no length announced: waitress counts and stops at the cap.
        with socket.create_connection(("127.0.0.1", server.port), timeout=30) as s:
            s.sendall(
                f"POST {path}/session/0 HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                "Content-Type: application/x-www-form-urlencoded\r\n"
                "Transfer-Encoding: chunked\r\n\r\n".encode()
            )
            chunk = b"x" * 8192
            try:
                for _ in range(MAX_BODY_BYTES // len(chunk) + 2):
                    s.sendall(b"%x\r\n" % len(chunk) + chunk + b"\r\n")
            except OSError:  # the server answered and closed while we were still sending
                pass
            reply = s.recv(4096).decode(errors="replace")
        assert reply.startswith("HTTP/1.1 413"), reply[:200]
        cmdline = open(f"/proc/{server.proc.pid}/cmdline", "rb").read()
        assert server.token.encode() not in cmdline
        assert os.environ.get("GAZEBOT_STUDY_ADMIN_TOKEN") is None
    finally:
        server.stop()
