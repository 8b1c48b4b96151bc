"""A whole participant in headless Chromium: consent, instructions, practice and every session,
with a SIGKILL and restart of the server in the middle of a session, a reload and a new tab; the
exported answers must equal what was clicked, nothing lost and nothing doubled."""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
import sys
import time

import numpy as np
import pytest
from study_web import REPO, StudyServer, form_token, http, render_tiny_study

from gazebot.apps.study.folder import load_study
from gazebot.apps.study.web.app import VISITOR_COOKIE

pytestmark = pytest.mark.browser

QUESTIONS = ("q1", "q2", "q3", "q4", "q5")


def _chromium() -> tuple[str, str]:
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    if not (browser and driver):
        pytest.skip(
            "no Chromium here: the browser tests need Debian's `chromium` and `chromium-driver` "
            "(`make test` installs them when run as root on Debian)"
        )
    return browser, driver


def _chrome(tmp_path, *extra: str):
    """Headless Chromium driven by chromedriver; ``extra``: more command-line switches."""
    webdriver = pytest.importorskip("selenium.webdriver")
    from selenium.webdriver.chrome.service import Service

    browser, chromedriver = _chromium()
    opts = webdriver.ChromeOptions()
    opts.binary_location = browser
    for arg in (
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        f"--user-data-dir={tmp_path / 'chromium-profile'}",
        "--autoplay-policy=no-user-gesture-required",
        "--window-size=900,1400",
        *extra,
    ):
        opts.add_argument(arg)
    # An explicit driver path: Selenium Manager would otherwise try to download one.
    d = webdriver.Chrome(service=Service(executable_path=chromedriver), options=opts)
    d.set_page_load_timeout(60)
    return d


@pytest.fixture
def driver(tmp_path):
    d = _chrome(tmp_path)
    yield d
    d.quit()


def _wait(predicate, timeout_s: float = 60.0, what: str = "condition"):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def _heading(d) -> str:
    """The page's heading, "" while a page is loading (no h1 yet, or the old one going)."""
    from selenium.common.exceptions import (
        NoSuchElementException,
        StaleElementReferenceException,
        WebDriverException,
    )
    from selenium.webdriver.common.by import By

    try:
        return d.find_element(By.TAG_NAME, "h1").text
    except (NoSuchElementException, StaleElementReferenceException):
        return ""
    except WebDriverException as exc:
        if _gone(exc):
            return ""
        raise


def _at(d, heading: str) -> None:
    """Wait for the page with ``heading`` (fails with the heading seen instead)."""
    try:
        _wait(lambda: _heading(d) == heading, timeout_s=30, what=heading)
    except AssertionError:
        raise AssertionError(f"expected page {heading!r}, at {_heading(d)!r}") from None


def _wait_for_questions(d) -> None:
    """Both videos play to the end, then the questions are enabled."""
    from selenium.webdriver.common.by import By

    _wait(
        lambda: d.find_element(By.ID, "questions").get_attribute("disabled") is None,
        what="both videos to play and the questions to appear",
    )
    ended = d.execute_script(
        "return [document.getElementById('v1').ended, document.getElementById('v2').ended]"
    )
    assert ended == [True, True]
    # One video at a time: the first is put away when the second plays.
    assert not d.find_element(By.ID, "v1").is_displayed()
    assert d.find_element(By.ID, "v2").is_displayed()


def _played_behaviors(d, study_dir) -> tuple[str, str]:
    """The behaviors of the two videos the page played, found by their bytes among the rendered
    handover videos (manifest.json names each file's behavior): what the participant saw, not
    what the server says it served."""
    manifest = json.loads((study_dir / "manifest.json").read_text())
    by_bytes = {
        (study_dir / rel).read_bytes(): v["behavior"] for rel, v in manifest["videos"].items()
    }
    srcs = d.execute_script(
        "return ['v1', 'v2'].map(function (id) { return document.getElementById(id).currentSrc; })"
    )
    out = []
    for src in srcs:
        status, _, body = http("GET", src)
        assert status == 200, src
        out.append(by_bytes[body])
    return out[0], out[1]


def _click_answers(d, answers: dict[str, int], comment: str) -> None:
    from selenium.webdriver.common.by import By

    for q, v in answers.items():
        d.find_element(By.ID, f"{q}-{v}").click()
    box = d.find_element(By.ID, "comment")
    box.clear()
    box.send_keys(comment)


def _submit(d) -> None:
    from selenium.webdriver.common.by import By

    old = d.find_element(By.TAG_NAME, "h1")
    d.find_element(By.ID, "next").click()
    _wait(lambda: _stale(old), what="the next page")


def _gone(exc: Exception) -> bool:
    """Chromium reports an element of a replaced document either as stale or, mid-navigation,
    as a node that "does not belong to the document": both mean the page was left."""
    from selenium.common.exceptions import StaleElementReferenceException

    return isinstance(exc, StaleElementReferenceException) or (
        "does not belong to the document" in str(exc)
    )


def _stale(element) -> bool:
    from selenium.common.exceptions import WebDriverException

    try:
        element.is_enabled()
    except WebDriverException as exc:
        if _gone(exc):
            return True
        raise
    return False


def test_whole_participant_in_chromium_survives_a_server_sigkill_mid_session(driver, tmp_path):
    from selenium.webdriver.common.by import By

    study_dir = tmp_path / "study"
    render_tiny_study(study_dir)
    study = load_study(study_dir)
    sessions = study.sessions_of(1)
    rng = np.random.default_rng(14)
    clicked: dict[int, dict[str, int]] = {}
    # `gazebot study serve study/` with a relative folder, exactly as the README shows it.
    server = StudyServer("study", cwd=tmp_path).start()
    try:
        d = driver
        link = server.links[1]  # participant 1's own link, from participant-links.csv
        d.get(link)
        _at(d, "Consent")
        csrf = form_token(d.page_source)  # this participant's forms' token, for a resent form
        d.find_element(By.ID, "consent").click()
        _submit(d)
        _at(d, "Instructions")
        assert "the robot's head movement" in d.find_element(By.ID, "instructions").text
        _submit(d)
        _at(d, "Practice session")
        # Skipping to the end does not count: the video plays again, all of it, first.
        _wait(lambda: d.execute_script("return document.getElementById('v1').readyState >= 1"))
        d.execute_script("var v = document.getElementById('v1'); v.currentTime = v.duration;")
        _wait_for_questions(d)
        played = d.execute_script(
            "var v = document.getElementById('v1'), t = 0;"
            "for (var i = 0; i < v.played.length; i++) t += v.played.end(i) - v.played.start(i);"
            "return [t, v.duration];"
        )
        assert played[0] >= 0.9 * played[1], played
        _click_answers(d, {q: 1 for q in QUESTIONS}, "practice")
        _submit(d)

        kill_at = sessions[len(sessions) // 2].session
        for s in sessions:
            _at(d, f"Session {s.session} of {len(sessions)}")
            _wait_for_questions(d)
            # The 1st video played is the plan's first behavior: "1st" answers mean what export
            # and analyze say they mean.
            assert _played_behaviors(d, study_dir) == (s.first, s.second)
            answers = {q: int(rng.integers(1, 3)) for q in QUESTIONS}
            clicked[s.session] = answers
            _click_answers(d, answers, f"comment {s.session}")
            if s.session == kill_at:
                # Mid-session: answers clicked but not submitted. Kill the server hard, then
                # restart it on the same port and reload: the page resumes at this session.
                server.kill()
                server.start()
                d.refresh()
                _at(d, f"Session {s.session} of {len(sessions)}")
                # A closed tab: a new one opens the same session.
                old = d.current_window_handle
                d.switch_to.new_window("tab")
                d.get(link)
                _at(d, f"Session {s.session} of {len(sessions)}")
                d.close()
                d.switch_to.window(old)
                _wait_for_questions(d)
                _click_answers(d, answers, f"comment {s.session}")
            # Two clicks in a row on the submit button: the page sends one form.
            d.execute_script("var b = document.getElementById('next'); b.click(); b.click();")
            _wait(
                lambda s=s: _heading(d) not in ("", f"Session {s.session} of {len(sessions)}"),
                what="the next page after a double click",
            )
        _at(d, "Thank you")
        # A resent form after the end (browser back + resubmit) changes nothing.
        last = sessions[-1].session
        # The browser's own cookie and Origin go with it, as a resubmitted form's would.
        visitor = d.get_cookie(VISITOR_COOKIE)["value"]
        headers = {"Cookie": f"{VISITOR_COOKIE}={visitor}", "Origin": server.base}
        resent = {"q1": "2", "csrf_token": csrf}
        status, _, _ = http("POST", f"{link}/session/{last}", resent, headers)
        assert status == 303
        # Without the cookie the same token is refused: it names this browser's visitor id.
        status, _, _ = http("POST", f"{link}/session/{last}", resent, {"Origin": server.base})
        assert status == 403
        d.get(link)
        # the page may still be building on a busy machine: wait for its text, not a snapshot
        _wait(lambda: "completed all" in d.page_source,
              what="the completed message")
        assert "completed all" in d.find_element(By.ID, "message").text
        d.get(f"{server.base}/p/1")  # a participant number is no link
        _wait(lambda: "No such participant link" in d.page_source, what="the not-found page")
    finally:
        server.stop()

    out = tmp_path / "responses.csv"
    cli = [sys.executable, "-m", "gazebot", "study"]
    env = {"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin"}
    subprocess.run([*cli, "export", str(study_dir), "--out", str(out)], check=True, env=env)
    with out.open() as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["session"]) for r in rows] == [s.session for s in sessions]  # once each
    for r, s in zip(rows, sessions, strict=True):
        assert {q: int(r[q]) for q in QUESTIONS} == clicked[s.session]
        assert r["comments"] == f"comment {s.session}"
        assert (r["first"], r["second"]) == (s.first, s.second)
        assert float(r["seconds"]) > 0.5  # at least both clips were watched
    analyzed = subprocess.run(
        [*cli, "analyze", str(out), "--json"], check=True, env=env, capture_output=True, text=True
    )
    assert json.loads(analyzed.stdout)["per_level"][""]["likability"]["participants"] == 1


def test_plain_http_lan_name_forms_work_and_an_opaque_origin_post_is_refused(tmp_path):
    """The server under a LAN name over plain HTTP (``study.test``, mapped to loopback): no
    secure context, so Chromium sends no ``Sec-Fetch-*`` headers. The site's own forms still
    go through (``Referrer-Policy: same-origin``: they carry their real ``Origin``), signing in
    included; a form posted from an opaque origin (``Origin: null``, as a no-referrer or
    sandboxed page of another site sends it) is refused and changes nothing."""
    from selenium.webdriver.common.by import By

    render_tiny_study(tmp_path / "study")
    server = StudyServer(
        tmp_path / "study", token="lan-admin-token", args=("--allowed-host", "study.test")
    ).start()
    d = _chrome(tmp_path, "--host-resolver-rules=MAP study.test 127.0.0.1")
    try:
        base = f"http://study.test:{server.port}"
        link = server.links[1].replace(server.base, base)
        d.get(link)
        _at(d, "Consent")
        assert d.execute_script("return window.isSecureContext") is False
        d.find_element(By.ID, "consent").click()
        _submit(d)
        _at(d, "Instructions")
        d.get(f"{base}/admin")
        _at(d, "Experimenter sign-in")
        d.find_element(By.NAME, "token").send_keys("lan-admin-token")
        d.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
        _at(d, "Study progress")
        # Another site's form, from an opaque origin, with a token of participant 2's page.
        target = server.links[2].replace(server.base, base)
        d.get(target)
        token = form_token(d.page_source)
        attack = (
            f"<form method=post action='{target}/consent'>"
            f"<input name=consent value=yes><input name=csrf_token value='{token}'></form>"
            "<script>document.forms[0].submit()</script>"
        )
        d.get("data:text/html," + attack)
        _at(d, "Forbidden")
        assert "Origin: null" in d.page_source
        store = load_study(tmp_path / "study").store()
        assert store.progress(2).mode is None and store.progress(1).mode == "video"
    finally:
        d.quit()
        server.stop()
