"""A study file (``DIR/study.yaml``): its pages and items asked in order and stored, bad answers
refused, attention checks recorded (and ending the study when asked), the public entry link for
recruiting services, the completion code or redirect, every answer exported, and a bad file
refused with its line and field named (through Flask's test client; the browser tests drive a
real one)."""

from __future__ import annotations

import csv
import re
import shutil
from pathlib import Path

import pytest
from study_web import render_tiny_study
from test_study_server import ANSWERS, Client

from gazebot.apps.study.export import EXPORT_COLUMNS, export_responses, participants_file
from gazebot.apps.study.folder import load_study
from gazebot.apps.study.study_file import STUDY_FILE, load_study_file
from gazebot.apps.study.web.app import create_app
from gazebot.core.config import ConfigError

REPO = Path(__file__).resolve().parents[3]

STUDY_YAML = """\
session_items:
  - id: confidence
    kind: likert
    text: How sure are you of your answers?
    points: 5
    anchors: [Not at all sure, Very sure]
  - id: notice
    kind: text
    text: What did you notice about the robot?
    required: false
pages:
  - id: demographics
    title: About you
    items:
      - {id: age, kind: number, text: Your age, min: 18, max: 99}
      - id: gender
        kind: choice
        text: Your gender
        options: [female, male, non-binary, prefer not to say]
      - id: familiarity
        kind: likert
        text: How familiar are you with robots?
        points: 7
        anchors: [Not at all, Very]
      - id: reading
        kind: attention
        text: To show you read this, choose "blue".
        options: [red, blue, green]
        answer: blue
  - id: closing
    title: Last questions
    at: after
    items:
      - {id: overall, kind: text, text: "Anything else about the study?", required: false}
entry:
  param: PROLIFIC_PID
completion:
  code: C0DE42
"""

DEMOGRAPHICS = {"age": "31", "gender": "female", "familiarity": "3", "reading": "blue"}
SESSION_ITEMS = {"confidence": "4", "notice": "it looked at the hand"}


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    out = tmp_path_factory.mktemp("sf") / "study"
    render_tiny_study(out)
    return out


def with_study_file(rendered: Path, tmp_path: Path, text: str = STUDY_YAML) -> Path:
    """A fresh copy of the rendered study (no answers) with ``text`` as its study file."""
    study = tmp_path / "study"
    shutil.copytree(rendered, study, ignore=shutil.ignore_patterns("responses.sqlite*"))
    (study / STUDY_FILE).write_text(text, encoding="utf-8")
    return study


def text(resp) -> str:
    return resp.get_data(as_text=True)


def run_sessions(c: Client, study: Path, pid: int = 1) -> None:
    """The practice and every session, each with the seed's answers and the session items."""
    for k in [0] + [s.session for s in load_study(study).sessions_of(pid)]:
        resp = c.post(f"/p/{pid}/session/{k}", data={**ANSWERS, **SESSION_ITEMS})
        assert resp.status_code == 303, text(resp)


def test_pages_and_items_are_asked_in_order_and_end_with_the_completion_code(rendered, tmp_path):
    study = with_study_file(rendered, tmp_path)
    c = Client(study)
    assert c.post("/p/1/consent", data={"consent": "yes"}).status_code == 303
    page = text(c.get("/p/1"))
    assert "About you" in page and "How familiar are you with robots?" in page
    assert 'type="number" name="age"' in page and "Not at all" in page
    # The instructions wait for the demographics page.
    c.post("/p/1/instructions")
    assert load_study(study).store().progress(1).instructions_at is None
    assert c.post("/p/1/page/demographics", data=DEMOGRAPHICS).status_code == 303
    assert "Instructions" in text(c.get("/p/1"))
    assert c.post("/p/1/instructions").status_code == 303
    page = text(c.get("/p/1"))
    assert "Practice session" in page and "How sure are you of your answers?" in page
    assert "7. How sure are you" in page and "8. What did you notice" in page  # after q1..q6
    run_sessions(c, study)
    page = text(c.get("/p/1"))
    assert "Last questions" in page
    assert c.post("/p/1/page/closing", data={"overall": "fine"}).status_code == 303
    done = c.get("/p/1")
    assert done.status_code == 200 and "C0DE42" in text(done)
    store = load_study(study).store()
    assert store.progress(1).pages == ("demographics", "closing")
    assert store.progress(1).failed_items == ()


def test_a_page_with_a_missing_or_bad_answer_is_refused_and_nothing_is_stored(rendered, tmp_path):
    study = with_study_file(rendered, tmp_path)
    c = Client(study)
    c.post("/p/1/consent", data={"consent": "yes"})
    bad = [
        ({**DEMOGRAPHICS, "age": ""}, "Question 1 (Your age) needs an answer."),
        ({**DEMOGRAPHICS, "age": "12"}, "expected a whole number from 18 to 99"),
        ({**DEMOGRAPHICS, "age": "3e1"}, "expected a whole number from 18 to 99"),
        ({**DEMOGRAPHICS, "gender": "robot"}, "Question 2 (Your gender): expected one of"),
        ({**DEMOGRAPHICS, "familiarity": "8"}, "expected a point from 1 to 7"),
        ({**DEMOGRAPHICS, "familiarity": "0"}, "expected a point from 1 to 7"),
    ]
    for form, message in bad:
        resp = c.post("/p/1/page/demographics", data=form)
        assert resp.status_code == 400, form
        assert message in text(resp), (form, text(resp))
        assert (
            'value="female" id="gender-1" required checked' in text(resp)
            or form["gender"] != "female"
        )  # what was given is shown again
    store = load_study(study).store()
    assert store.progress(1).pages == () and store.item_answers() == []
    # A page that is not the current step is refused.
    assert c.post("/p/1/page/closing", data={"overall": "x"}).status_code == 409
    # A session item out of range refuses the session, the seed's answers with it.
    c.post("/p/1/page/demographics", data=DEMOGRAPHICS)
    c.post("/p/1/instructions")
    resp = c.post("/p/1/session/0", data={**ANSWERS, "confidence": "6"})
    assert resp.status_code == 400 and "expected a point from 1 to 5" in text(resp)
    assert store.progress(1).answered == ()


def test_a_double_submitted_page_keeps_the_first_answers(rendered, tmp_path):
    study = with_study_file(rendered, tmp_path)
    c = Client(study)
    c.post("/p/1/consent", data={"consent": "yes"})
    c.post("/p/1/page/demographics", data=DEMOGRAPHICS)
    assert c.post("/p/1/page/demographics", data={**DEMOGRAPHICS, "age": "50"}).status_code == 303
    ages = [a.value for a in load_study(study).store().item_answers() if a.item == "age"]
    assert ages == ["31"]


def test_a_failed_attention_check_is_recorded_and_exported(rendered, tmp_path):
    study = with_study_file(rendered, tmp_path)
    c = Client(study)
    c.post("/p/1/consent", data={"consent": "yes"})
    c.post("/p/1/page/demographics", data={**DEMOGRAPHICS, "reading": "red"})
    store = load_study(study).store()
    (failure,) = store.attention_failures()
    assert (failure.participant, failure.item, failure.given, failure.expected) == (
        1,
        "reading",
        "red",
        "blue",
    )
    assert "Instructions" in text(c.get("/p/1"))  # on_failure: record, the study goes on
    c.post("/p/1/instructions")
    run_sessions(c, study)
    out, _ = export_responses(study, tmp_path / "r.csv")
    rows = list(csv.DictReader(out.open()))
    assert {r["attention_failures"] for r in rows} == {"reading"}
    (p,) = list(csv.DictReader(participants_file(out).open()))
    assert (p["status"], p["attention_failures"], p["reading"]) == ("started", "reading", "red")


def test_an_attention_check_that_ends_the_study_shows_the_screen_out_page(rendered, tmp_path):
    yaml_text = STUDY_YAML.replace("answer: blue", "answer: blue\n        on_failure: end")
    yaml_text = yaml_text.replace(
        "  code: C0DE42", "  code: C0DE42\n  screen_out_url: https://example.org/out?cc={code}"
    )
    yaml_text += "  screen_out_code: OUT7\n"
    study = with_study_file(rendered, tmp_path, yaml_text)
    c = Client(study)
    c.post("/p/1/consent", data={"consent": "yes"})
    c.post("/p/1/page/demographics", data={**DEMOGRAPHICS, "reading": "green"})
    end = c.get("/p/1")
    assert end.status_code == 303 and end.headers["Location"] == "https://example.org/out?cc=OUT7"
    assert c.post("/p/1/instructions").status_code == 303
    assert load_study(study).store().progress(1).instructions_at is None  # nothing goes on
    assert c.post("/p/1/session/0", data=ANSWERS).status_code == 409
    export_responses(study, tmp_path / "r.csv")
    (p,) = list(csv.DictReader(participants_file(tmp_path / "r.csv").open()))
    assert (p["status"], p["age"], p["reading"]) == ("ended", "31", "green")


def test_entry_link_assigns_plan_rows_in_order_and_keeps_an_id_on_its_row(rendered, tmp_path):
    study = with_study_file(rendered, tmp_path)
    c = Client(study)
    web = c.web

    def enter(query: str):
        return c.c.get(f"/start?{query}")

    first = enter("PROLIFIC_PID=5f1a2b&STUDY_ID=x")
    assert first.status_code == 303 and first.headers["Location"].endswith(web.link_path(1))
    # Participant 2 started through their own link: the entry link skips that row.
    c.post("/p/2/consent", data={"consent": "yes"})
    assert enter("PROLIFIC_PID=other").headers["Location"].endswith(web.link_path(3))
    assert enter("PROLIFIC_PID=5f1a2b").headers["Location"].endswith(web.link_path(1))
    for query in ("", "PROLIFIC_PID=", "PROLIFIC_PID=%3Cscript%3E", "pid=abc"):
        resp = enter(query)
        assert resp.status_code == 400 and "PROLIFIC_PID" in text(resp), query
    for k in range(4):
        enter(f"PROLIFIC_PID=more{k}")
    full = enter("PROLIFIC_PID=late")
    assert full.status_code == 409 and "full" in text(full)
    assert load_study(study).store().external_ids() == {
        1: "5f1a2b",
        3: "other",
        4: "more0",
        5: "more1",
        6: "more2",
    }


def test_entry_link_takes_a_configured_parameter_and_is_absent_without_entry(rendered, tmp_path):
    study = with_study_file(rendered, tmp_path, STUDY_YAML.replace("PROLIFIC_PID", "workerId"))
    c = Client(study)
    assert c.c.get("/start?workerId=A1B2").status_code == 303
    assert c.c.get("/start?PROLIFIC_PID=A1B2").status_code == 400
    plain = with_study_file(rendered, tmp_path / "plain", "pages: []\n")
    assert Client(plain).c.get("/start?PROLIFIC_PID=A1B2").status_code == 404


def test_completion_redirect_carries_the_code(rendered, tmp_path):
    yaml_text = STUDY_YAML.replace(
        "  code: C0DE42",
        "  code: C0DE42\n  redirect_url: https://app.prolific.com/submissions/complete?cc={code}",
    )
    study = with_study_file(rendered, tmp_path, yaml_text)
    c = Client(study)
    c.post("/p/1/consent", data={"consent": "yes"})
    c.post("/p/1/page/demographics", data=DEMOGRAPHICS)
    c.post("/p/1/instructions")
    run_sessions(c, study)
    c.post("/p/1/page/closing", data={})
    done = c.get("/p/1")
    assert done.status_code == 303
    assert done.headers["Location"] == "https://app.prolific.com/submissions/complete?cc=C0DE42"


def test_export_has_every_answer_of_the_study_file(rendered, tmp_path):
    study = with_study_file(rendered, tmp_path)
    c = Client(study)
    c.c.get("/start?PROLIFIC_PID=ext-1")
    c.post("/p/1/consent", data={"consent": "yes"})
    c.post("/p/1/page/demographics", data=DEMOGRAPHICS)
    c.post("/p/1/instructions")
    run_sessions(c, study)
    c.post("/p/1/page/closing", data={"overall": "thanks"})
    out, n = export_responses(study, tmp_path / "r.csv", include_practice=True)
    with out.open() as fh:
        reader = csv.DictReader(fh)
        rows = list(reader)
        columns = tuple(reader.fieldnames or ())
    items = ("confidence", "notice", "age", "gender", "familiarity", "reading", "overall")
    assert columns == (*EXPORT_COLUMNS, "external_id", "attention_failures", *items)
    assert n == len(rows) == 1 + len(load_study(study).sessions_of(1))
    for r in rows:
        assert r["external_id"] == "ext-1" and r["attention_failures"] == ""
        assert {k: r[k] for k in SESSION_ITEMS} == SESSION_ITEMS
        assert {k: r[k] for k in DEMOGRAPHICS} == DEMOGRAPHICS
        assert r["overall"] == "thanks"
    (p,) = list(csv.DictReader(participants_file(out).open()))
    assert p["status"] == "finished" and p["external_id"] == "ext-1" and p["age"] == "31"


def test_without_a_study_file_the_export_has_the_seed_columns_only(rendered, tmp_path):
    study = tmp_path / "study"
    shutil.copytree(rendered, study, ignore=shutil.ignore_patterns("responses.sqlite*"))
    c = Client(study)
    c.post("/p/1/consent", data={"consent": "yes"})
    c.post("/p/1/instructions")
    c.post("/p/1/session/0", data=ANSWERS)
    c.post("/p/1/session/1", data=ANSWERS)
    out, _ = export_responses(study, tmp_path / "r.csv")
    assert tuple(next(csv.reader(out.open()))) == EXPORT_COLUMNS
    assert not participants_file(out).exists()


BAD_FILES = [
    (
        "session_items:\n  - {id: x, kind: likert, text: T, points: 12, anchors: [a, b]}\n",
        2,
        "session_items[0].points",
        "less than or equal to 11",
    ),
    (
        "pages:\n  - id: p\n    title: P\n    items:\n      - id: a\n        kind: likert\n"
        "        text: T\n        points: 5\n        anchors: [a, b, c]\n",
        5,
        "pages[0].items[0]",
        "2 labels (both ends) or 5",
    ),
    (
        "pages:\n  - id: p\n    title: P\n    items:\n      - id: a\n        kind: attention\n"
        "        text: T\n        options: [x, y]\n        answer: z\n",
        5,
        "pages[0].items[0]",
        "answer 'z' is not one of the options",
    ),
    ("session_items:\n  - {id: q1, kind: text, text: T}\n", None, "<root>", "export's own"),
    (
        "session_items:\n  - {id: x, kind: slider, text: T}\n",
        2,
        "session_items[0]",
        "does not match any of the expected tags",
    ),
    ("entry:\n  param: 'a b'\n", 2, "entry.param", "match pattern"),
    (
        "completion:\n  redirect_url: javascript:alert(1)\n",
        2,
        "completion.redirect_url",
        "an http(s) URL with a host",
    ),
    ("pagez: []\n", 1, "pagez", "unknown key (known: "),
]


@pytest.mark.parametrize(("body", "line", "field", "expected"), BAD_FILES)
def test_a_bad_study_file_names_the_file_line_and_field(tmp_path, body, line, field, expected):
    path = tmp_path / STUDY_FILE
    path.write_text(body)
    with pytest.raises(ConfigError) as err:
        load_study_file(path)
    msg = str(err.value)
    where = f"{path}: field '{field}'" if line is None else f"{path}:{line}: {field}: "
    assert msg.startswith(where) and expected in msg, msg


def test_a_study_file_with_a_yaml_syntax_error_names_its_line_and_column(tmp_path):
    path = tmp_path / STUDY_FILE
    path.write_text("pages: [\n")
    with pytest.raises(ConfigError, match=rf"^{re.escape(str(path))}:2:1: invalid YAML: "):
        load_study_file(path)


def test_serve_refuses_a_bad_study_file_before_serving(rendered, tmp_path):
    study = with_study_file(rendered, tmp_path, "pagez: []\n")
    with pytest.raises(ConfigError, match=r"study\.yaml:1: pagez: unknown key"):
        create_app(str(study))


def test_the_documented_example_is_a_valid_study_file(tmp_path):
    doc = (REPO / "docs" / "study-file.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```yaml\n(.*?)```", doc, flags=re.S)
    assert blocks, "docs/study-file.md has no YAML example"
    path = tmp_path / STUDY_FILE
    path.write_text(blocks[0])
    sf = load_study_file(path)
    kinds = {i.kind for i in sf.items()}
    assert kinds == {"likert", "text", "choice", "number", "attention"}
    assert sf.entry is not None and sf.completion.code


def test_session_page_has_play_only_controls_below_the_video(rendered, tmp_path):
    study = with_study_file(rendered, tmp_path, "pages: []\n")
    c = Client(study)
    c.post("/p/1/consent", data={"consent": "yes"})
    c.post("/p/1/instructions")
    page = text(c.get("/p/1"))
    videos = re.findall(r"<video [^>]*>", page)
    assert len(videos) == 2 and not any(re.search(r"\scontrols[\s>]", v) for v in videos)
    # The player's button and bar come after both videos: nothing is drawn over them.
    assert page.index('id="play"') > page.rindex("<video")
    assert '<button type="button" id="play"' in page
    assert '<input type="range"' not in page  # no scrubbing bar
