"""In headless Chromium: the session page's play-only controls cannot seek (a script setting
``currentTime``, arrow keys and End on the video, a faster playback rate: the position stays),
they sit below the video and work from the keyboard; and a study from a study file (a Likert
item after each pair, a demographics page, attention checks, an external id from the entry link)
completes end to end with the completion code shown and every answer exported."""

from __future__ import annotations

import csv
import subprocess
import sys

import pytest
from study_web import REPO, StudyServer, render_tiny_study
from test_study_browser import _at, _chrome, _click_answers, _submit, _wait, _wait_for_questions

from gazebot.apps.study.folder import load_study
from gazebot.apps.study.study_file import STUDY_FILE

pytestmark = pytest.mark.browser

QUESTIONS = ("q1", "q2", "q3", "q4", "q5")


@pytest.fixture
def driver(tmp_path):
    d = _chrome(tmp_path)
    yield d
    d.quit()


def _video(d, prop: str):
    return d.execute_script(f"return document.getElementById('v1').{prop};")


def test_play_only_controls_cannot_seek_and_work_from_the_keyboard(driver, tmp_path):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    render_tiny_study(tmp_path / "study", participants=6, duration=4.0)
    with StudyServer(tmp_path / "study") as server:
        d = driver
        d.get(server.links[1])
        _at(d, "Consent")
        d.find_element(By.ID, "consent").click()
        _submit(d)
        _at(d, "Instructions")
        _submit(d)
        _at(d, "Practice session")
        assert _video(d, "controls") is False
        # The controls are below the video, nothing over it.
        video = d.find_element(By.ID, "v1").rect
        for el in ("play", "position"):
            box = d.find_element(By.ID, el).rect
            assert box["y"] >= video["y"] + video["height"], el
        _wait(lambda: _video(d, "currentTime") > 0.5, what="the video to play")
        d.execute_script("document.getElementById('v1').pause();")
        _wait(lambda: _video(d, "paused") and not _video(d, "seeking"), what="a pause")
        at = _video(d, "currentTime")
        assert 0.5 < at < 3.5

        def settled():
            return not _video(d, "seeking")

        # A script seeking forward, then backward: undone each time.
        for target in ("v.duration - 0.05", "0", "2.9"):
            d.execute_script(f"var v = document.getElementById('v1'); v.currentTime = {target};")
            _wait(settled, what="the seek to settle")
            d.execute_script("return 0")  # one more turn of the page's event loop
            _wait(settled, what="the undo to settle")
            assert abs(_video(d, "currentTime") - at) < 0.05, target
        # Keys on the video (focused by a click) and on the page: nothing moves.
        d.execute_script("document.getElementById('v1').focus();")
        ActionChains(d).send_keys(Keys.ARROW_RIGHT, Keys.END, Keys.ARROW_LEFT, Keys.HOME).perform()
        d.find_element(By.TAG_NAME, "body").send_keys(Keys.ARROW_RIGHT, Keys.END)
        _wait(settled, what="keys to settle")
        assert abs(_video(d, "currentTime") - at) < 0.05
        assert _video(d, "paused") is True
        # A faster playback rate is put back.
        d.execute_script("document.getElementById('v1').playbackRate = 8;")
        _wait(lambda: _video(d, "playbackRate") == 1, what="the rate put back")
        # Nothing was played past where playing had got.
        played = d.execute_script(
            "var v = document.getElementById('v1'), t = 0;"
            "for (var i = 0; i < v.played.length; i++) t += v.played.end(i) - v.played.start(i);"
            "return t;"
        )
        assert played <= at + 0.05
        # The Play button, reached and pressed from the keyboard, resumes where it was.
        play = d.find_element(By.ID, "play")
        d.execute_script("document.getElementById('play').focus();")
        assert d.switch_to.active_element == play
        play.send_keys(Keys.SPACE)
        _wait(lambda: not _video(d, "paused"), what="Play from the keyboard")
        assert _video(d, "currentTime") >= at - 0.05
        _wait_for_questions(d)


STUDY_YAML = """\
session_items:
  - id: confidence
    kind: likert
    text: How sure are you of your answers for this pair?
    points: 5
    anchors: [Not at all sure, Very sure]
pages:
  - id: demographics
    title: About you
    items:
      - {id: age, kind: number, text: Your age in years, min: 18, max: 99}
      - id: gender
        kind: choice
        text: Your gender
        options: [female, male, non-binary, prefer not to say]
      - id: familiarity
        kind: likert
        text: How familiar are you with robots?
        points: 7
        anchors: [Not at all familiar, Very familiar]
      - id: reading
        kind: attention
        text: To show that you read the questions, choose "blue" here.
        options: [red, blue, green]
        answer: blue
        on_failure: end
      - id: careful
        kind: attention
        text: Choose "often" here.
        options: [never, often]
        answer: often
entry:
  param: PROLIFIC_PID
completion:
  code: DONE2026
"""


def test_a_study_file_study_completes_in_chromium_and_exports_every_answer(driver, tmp_path):
    from selenium.webdriver.common.by import By

    study_dir = tmp_path / "study"
    render_tiny_study(study_dir)
    (study_dir / STUDY_FILE).write_text(STUDY_YAML)
    clicked: dict[int, dict[str, int]] = {}
    confidence: dict[int, int] = {}
    with StudyServer(study_dir) as server:
        d = driver
        d.get(f"{server.base}/start?PROLIFIC_PID=5f1a2b3c&STUDY_ID=s1&SESSION_ID=x9")
        _at(d, "Consent")
        d.find_element(By.ID, "consent").click()
        _submit(d)
        _at(d, "About you")
        d.find_element(By.ID, "age").send_keys("34")
        d.find_element(By.ID, "gender-3").click()  # non-binary
        d.find_element(By.ID, "familiarity-6").click()
        d.find_element(By.ID, "reading-2").click()  # blue: passed
        d.find_element(By.ID, "careful-1").click()  # never: failed, recorded only
        _submit(d)
        _at(d, "Instructions")
        _submit(d)
        participant = next(p for p, url in server.links.items() if url == d.current_url)
        sessions = [0] + [s.session for s in load_study(study_dir).sessions_of(participant)]
        for k, session in enumerate(sessions):
            _at(d, "Practice session" if k == 0 else f"Session {k} of {len(sessions) - 1}")
            _wait_for_questions(d)
            answers = {q: 1 + (k + j) % 2 for j, q in enumerate(QUESTIONS)}
            clicked[session] = answers
            _click_answers(d, answers, f"comment {session}")
            confidence[session] = 1 + k % 5
            d.find_element(By.ID, f"confidence-{confidence[session]}").click()
            _submit(d)
        _at(d, "Thank you")
        assert d.find_element(By.ID, "code").text == "DONE2026"

    out = tmp_path / "responses.csv"
    env = {"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin"}
    cli = [sys.executable, "-m", "gazebot", "study", "export", str(study_dir), "--out", str(out)]
    printed = subprocess.run(
        [*cli, "--include-practice"], check=True, env=env, text=True, capture_output=True
    ).stdout
    assert "responses-participants.csv" in printed
    with out.open() as fh:
        rows = list(csv.DictReader(fh))
    assert [int(r["session"]) for r in rows] == sessions
    for r in rows:
        s = int(r["session"])
        assert int(r["participant"]) == participant
        assert {q: int(r[q]) for q in QUESTIONS} == clicked[s]
        assert r["comments"] == f"comment {s}"
        assert int(r["confidence"]) == confidence[s]
        assert (r["age"], r["gender"], r["familiarity"]) == ("34", "non-binary", "6")
        assert (r["reading"], r["careful"]) == ("blue", "never")
        assert r["external_id"] == "5f1a2b3c" and r["attention_failures"] == "careful"
    with (tmp_path / "responses-participants.csv").open() as fh:
        (p,) = list(csv.DictReader(fh))
    assert (p["participant"], p["external_id"], p["status"]) == (
        str(participant),
        "5f1a2b3c",
        "finished",
    )
    assert (p["age"], p["attention_failures"]) == ("34", "careful")
