"""Hypothesis over the study server's inputs (form fields, the participant code, link tokens,
session numbers): every answer is a page with a 2xx/3xx/4xx status, never a 500 or a
traceback, and nothing but a complete, valid answer is stored."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from study_web import render_tiny_study

from gazebot.apps.study.web.app import ADMIN_COOKIE, VISITOR_COOKIE, create_app

FUZZ = settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
ALLOWED = {200, 303, 400, 403, 404, 405, 409, 413}
FIELD = st.one_of(
    st.text(max_size=40),
    st.sampled_from(["1", "2", "1 ", "²", "١", "0", "3", "-1", "1e0", "true", "", "\x00"]),
)
FORM = st.dictionaries(
    st.sampled_from(["q1", "q2", "q3", "q4", "q5", "comment", "consent", "session", "token",
                     "csrf_token", "x"]),
    FIELD,
    max_size=8,
)


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    out = tmp_path_factory.mktemp("fuzz") / "study"
    render_tiny_study(out)
    # local_admin: a loopback client is the experimenter, so the fuzzed forms reach the views.
    return create_app(str(out), admin_token="admin-token-1234", local_admin=True)


VISITOR = "fuzz-visitor-0123456789"
SAME_ORIGIN = {"Origin": "http://localhost"}


def _browser(app, remote="127.0.0.1"):
    """A test client as a browser: a visitor cookie, and the site's Origin on its POSTs."""
    c = app.test_client()
    c.environ_base["REMOTE_ADDR"] = remote
    c.environ_base["HTTP_ORIGIN"] = SAME_ORIGIN["Origin"]
    c.set_cookie(VISITOR_COOKIE, VISITOR)
    return c


def _check(resp) -> None:
    assert resp.status_code in ALLOWED, resp.status_code
    assert b"Traceback" not in resp.data and b"Something went wrong" not in resp.data


@pytest.mark.timeout(300)
@FUZZ
@given(form=FORM, k=st.integers(-3, 2**70), who=st.integers(1, 6), valid_csrf=st.booleans())
def test_participant_forms_with_any_fields(app, form, k, who, valid_csrf):
    web = app.extensions["gazebot_study"]
    c = _browser(app)
    link = web.link_path(who)
    if valid_csrf:
        form = {**form, "csrf_token": web.csrf("p:" + web.links[who], VISITOR)}
    for path in (f"{link}/consent", f"{link}/instructions", f"{link}/session/{k}"):
        _check(c.post(path, data=form))
    _check(c.get(link))
    for a in web.store.answers(include_practice=True):
        assert set(a.answers.values()) <= {1, 2} and len(a.comment) <= 4000


@pytest.mark.timeout(300)
@FUZZ
@given(form=FORM, who=st.integers(-5, 2**70), remote=st.sampled_from(["127.0.0.1", "192.0.2.9"]))
def test_experimenter_forms_with_any_fields(app, form, who, remote):
    web = app.extensions["gazebot_study"]
    c = _browser(app, remote)
    _check(c.get("/admin"))  # from loopback: an admin session (cookie) and its forms' token
    cookie = c.get_cookie(ADMIN_COOKIE)
    admin_csrf = web.csrf("admin", cookie.value.split(".")[0]) if cookie else "none"
    _check(c.post(f"/admin/in-person/{who}", data={**form, "csrf_token": admin_csrf}))
    _check(c.post("/admin/login", data={**form, "csrf_token": web.csrf("login", VISITOR)}))
    _check(c.get(f"/admin/in-person/{who}"))


@pytest.mark.timeout(300)
@FUZZ
@given(code=st.text(max_size=40), token=st.text(min_size=1, max_size=40).filter(
    lambda s: "/" not in s and s not in (".", "..")))
def test_any_participant_code_or_link_token(app, code, token):
    c = app.test_client()
    _check(c.get("/", query_string={"participant": code}))
    _check(c.get(f"/p/{token}"))
    _check(c.get(f"/p/{token}/video/0/1.mp4"))
