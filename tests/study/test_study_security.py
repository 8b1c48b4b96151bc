"""The study server as an attacker or a careless user meets it: relative study folders, links
only their participant can use, CSRF tokens and an origin check on every POST, bodies capped
before they are read, security headers, the admin token kept out of URLs and ``ps``, and a
log flood rate-limited."""

from __future__ import annotations

import csv
import logging
import os
import socket
import stat

import pytest
from study_web import StudyServer, form_token, http, render_tiny_study

from gazebot.study.web.app import create_app
from gazebot.study.web.security import MAX_BODY_BYTES, RateLimitFilter, rate_limit_logs
from gazebot.study.web.server import ADMIN_TOKEN_FILE, admin_token_source


@pytest.fixture(scope="module")
def study_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("sec") / "study"
    render_tiny_study(out)
    return out


def _client(study_dir, **kw):
    app = create_app(str(study_dir), admin_token="admin-token-1234", **kw)
    c = app.test_client()
    c.environ_base["REMOTE_ADDR"] = "127.0.0.1"
    return app.extensions["gazebot_study"], c


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
    assert c.post(f"{link}/consent", data={"consent": "yes"}).status_code == 403
    bad = {"consent": "yes", "csrf_token": web.csrf("admin")}  # another scope's token
    assert c.post(f"{link}/consent", data=bad).status_code == 403
    assert web.store.progress(3).mode is None
    page = c.get(link).get_data(as_text=True)
    good = {"consent": "yes", "csrf_token": form_token(page)}
    assert c.post(f"{link}/consent", data=good).status_code == 303
    # The experimenter's forms too: a cross-site form cannot lock a participant out.
    assert c.post("/admin/in-person/4", data={"session": "1"}).status_code == 403
    assert web.store.progress(4).mode is None


@pytest.mark.parametrize(
    ("headers", "allowed"),
    [
        ({"Origin": "http://evil.example"}, False),
        ({"Origin": "http://localhost.evil.example"}, False),
        ({"Origin": "null", "Sec-Fetch-Site": "cross-site"}, False),
        ({"Sec-Fetch-Site": "same-site"}, False),
        ({"Origin": "http://localhost"}, True),
        # Referrer-Policy: no-referrer makes a browser send "Origin: null" on its own forms.
        ({"Origin": "null", "Sec-Fetch-Site": "same-origin"}, True),
        ({}, True),  # not a browser: the CSRF token alone decides
    ],
)
def test_a_post_from_another_site_is_refused_even_with_a_valid_token(study_dir, headers, allowed):
    web, c = _client(study_dir)
    data = {"session": "1", "csrf_token": web.csrf("admin")}
    resp = c.post("/admin/in-person/5", data=data, headers=headers)
    assert (resp.status_code != 403) == allowed, resp.status_code
    if not allowed:
        assert b"may not post here" in resp.data


def test_a_body_over_the_cap_is_refused_with_413(study_dir):
    web, c = _client(study_dir)
    link = web.link_path(2)
    big = {"comment": "x" * (MAX_BODY_BYTES + 1), "csrf_token": web.csrf("p:" + web.links[2])}
    resp = c.post(f"{link}/session/0", data=big)
    assert resp.status_code == 413 and b"Too large" in resp.data
    assert web.store.progress(2).answered == ()


def test_every_response_has_the_security_headers(study_dir):
    web, c = _client(study_dir)
    for path in ("/", web.link_path(1), "/admin", "/nowhere", f"{web.link_path(1)}/video/0/1.mp4"):
        h = c.get(path).headers
        csp = h["Content-Security-Policy"]
        assert "frame-ancestors 'none'" in csp and "default-src 'none'" in csp
        assert "'unsafe-inline'" not in csp
        assert h["Referrer-Policy"] == "no-referrer"
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
