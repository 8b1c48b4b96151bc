"""The study's web pages (Flask): one step per page for a participant, an experimenter's view.

Participant ``N`` opens their own link ``/p/TOKEN`` (a random token per participant, see
:mod:`gazebot.apps.study.web.security`; ``study serve`` writes them to ``participant-links.csv``)
and
is shown the step they are at, derived from the stored answers (:mod:`gazebot.apps.study.store`):
consent, instructions, the practice session, then the plan's sessions in order, then a closing
page. Every form posts to its step and is answered with a redirect back to ``/p/TOKEN``
(post/redirect/get), so a reload never resubmits and a double submit of a session stores it once.

A session page plays the first handover video, then the second (each with the caption naming the
head or the eyes, as the seed's captions did); the five questions are enabled once both have
played to the end, and all five are required (the comment is optional, as the seed's question 6
says).

A study file (``DIR/study.yaml``, :mod:`gazebot.apps.study.study_file`) adds pages of items
before the instructions and after the last session, items after every pair, attention checks, a
public entry link ``/start?PARAM=ID`` for recruiting services and a completion code or redirect;
without it the study is the seed's.

The videos have no browser controls: a Play button below the video starts it (and resumes it
if the browser paused it), a bar shows the position, and any seek (a script setting
``currentTime``, a key) is undone, so a participant sees each handover whole and in order.

The experimenter's pages under ``/admin`` (after signing in with the admin token; from the
loopback interface without it only when ``local_admin`` is asked for) show every participant's
progress and link and let the experimenter enter an in-person participant's answers after each
live pair, the plan telling which behavior comes first.
"""

from __future__ import annotations

import ipaddress
import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime, timezone
from functools import wraps

from flask import (
    Flask,
    abort,
    g,
    make_response,
    redirect,
    render_template,
    request,
    send_file,
    url_for,
)

from gazebot.apps.study.folder import PRACTICE, StudyFolder, load_study
from gazebot.apps.study.in_person import FAMILIARITY_QUESTION
from gazebot.apps.study.plan import Session
from gazebot.apps.study.questionnaire import (
    COMMENT_QUESTION,
    QUESTIONS,
    attention_caption,
    instructions,
    questions,
)
from gazebot.apps.study.store import Progress, ResponseStore
from gazebot.apps.study.study_file import DEFAULT, StudyFile, study_file_of
from gazebot.apps.study.web.items import parse_items
from gazebot.apps.study.web.security import (
    ADMIN_SESSION_MAX_AGE_S,
    LOOPBACK_HOSTS,
    MAX_BODY_BYTES,
    admin_cookie,
    admin_session_of,
    cross_site_reason,
    csrf_token,
    host_allowed,
    is_link_token,
    new_token,
    security_headers,
    tokens_equal,
)

ADMIN_COOKIE = "gazebot_admin"  # the experimenter's signed session id
VISITOR_COOKIE = "gazebot_visitor"  # any other browser's random id, which its forms' tokens name
CONSENT_FILE = "consent.txt"  # the study's own consent text, in the study folder
DEFAULT_CONSENT = (
    "You are invited to take part in a study of how people perceive a robot's gaze when a person "
    "hands an object to the robot. You will watch short videos of handovers and answer a few "
    "questions after each pair of videos. Taking part is voluntary: you may stop at any time. "
    "Your answers are stored under your participant number only."
)
MAX_COMMENT = 4000  # characters kept of a comment
MAX_REACH_START_S = 60.0  # a measured reach-start time beyond +-this is a typo, not a handover
ENTRY_PATH = "/start"  # the study file's public entry link
EXTERNAL_ID_RE = re.compile(r"[A-Za-z0-9_.:-]{1,128}")  # a recruiting service's participant id


@dataclass(frozen=True)
class Step:
    """Where a participant is: ``kind`` is ``consent``, ``page`` (a study file's page, with
    ``page``: its id), ``instructions``, ``session`` (with ``session``: 0 for the practice, else
    the plan's session number), ``done`` or ``ended`` (an attention check ended the study)."""

    kind: str
    session: int | None = None
    page: str | None = None


def current_step(
    study: StudyFolder,
    store: ResponseStore,
    participant: int,
    prog: Progress | None = None,
    study_file: StudyFile = DEFAULT,
) -> Step:
    """The participant's next step, from the stored progress only (``prog``: already read):
    consent, the study file's ``before`` pages, instructions, the practice and the plan's
    sessions, its ``after`` pages, done."""
    prog = prog or store.progress(participant)
    if prog.consent_at is None:
        return Step("consent")
    if study_file.ends_on(prog.failed_items):
        return Step("ended")
    in_person = prog.mode == "in-person"  # the experimenter enters the sessions' answers only
    pages_done = set(prog.pages)
    for page in [] if in_person else study_file.pages_at("before"):
        if page.id not in pages_done:
            return Step("page", page=page.id)
    if prog.instructions_at is None:
        return Step("instructions")
    done = set(prog.answered)
    # In person the experimenter enters the plan's sessions only: there is no practice to wait for.
    practice = [] if in_person else [PRACTICE]
    for k in practice + [s.session for s in study.sessions_of(participant)]:
        if k not in done:
            return Step("session", k)
    for page in [] if in_person else study_file.pages_at("after"):
        if page.id not in pages_done:
            return Step("page", page=page.id)
    return Step("done")


def _utc(t: float | None) -> str:
    if t is None:
        return ""
    return datetime.fromtimestamp(t, timezone.utc).strftime("%Y-%m-%d %H:%M:%S")


def _is_loopback(addr: str | None) -> bool:
    try:
        return addr is not None and ipaddress.ip_address(addr).is_loopback
    except ValueError:
        return False


def _step_label(prog: Progress, step: Step) -> str:
    """What the experimenter's table says a participant is at."""
    if prog.finished_at is not None:
        return "finished"
    if prog.mode is None:
        return "not started"
    if step.kind == "session":
        return "practice" if step.session == PRACTICE else f"session {step.session}"
    if step.kind == "page":
        return f"page {step.page}"
    return step.kind


@dataclass(frozen=True)
class StudyWeb:
    """What the app knows of its study (``app.extensions["gazebot_study"]``): the folder, its
    answers, each participant's link token and the CSRF key (also the admin cookie's)."""

    study: StudyFolder
    store: ResponseStore
    links: dict[int, str]
    csrf_key: bytes
    study_file: StudyFile = DEFAULT

    def link_path(self, participant: int) -> str:
        """``/p/TOKEN`` of a participant."""
        return f"/p/{self.links[participant]}"

    def csrf(self, scope: str, session: str) -> str:
        """The CSRF token of the forms of ``scope`` (``p:TOKEN``, ``login`` or ``admin``) for
        the browser whose cookie holds the random id ``session`` (its visitor id, or for
        ``admin`` its admin session id)."""
        return csrf_token(self.csrf_key, scope, session)


def create_app(
    study_dir: str,
    admin_token: str | None = None,
    local_admin: bool = False,
    allowed_hosts: tuple[str, ...] = LOOPBACK_HOSTS,
    admin_session_s: float = ADMIN_SESSION_MAX_AGE_S,
    clock: Callable[[], float] = time.time,
) -> Flask:
    """The Flask app of the rendered study in ``study_dir`` (answers in
    ``study_dir/responses.sqlite``). ``admin_token``: the token that opens ``/admin`` (default:
    a random one, in ``app.config["ADMIN_TOKEN"]``); ``local_admin``: also open it without the
    token to requests from the loopback interface (any user or program on this machine, and on
    Debian a browser on it that opens the machine's own name, which resolves to 127.0.1.1);
    ``allowed_hosts``: the names a request's ``Host`` may give (an IP address is always
    accepted, see :func:`~gazebot.apps.study.web.security.host_allowed`), anything else is 400;
    ``admin_session_s``: how long a sign-in lasts (then the token is asked again); ``clock``:
    the Unix time in s. A study file ``study_dir/study.yaml`` that is not valid raises
    :class:`~gazebot.core.config.ConfigError` naming its line and field."""
    study = load_study(study_dir)
    sf = study_file_of(study.root)
    store = study.store()
    web = StudyWeb(study, store, store.links(study.participants), store.secret("csrf"), sf)
    pages = {pg.id: pg for pg in sf.pages}
    by_token = {t: p for p, t in web.links.items()}
    app = Flask(__name__)
    app.config["ADMIN_TOKEN"] = admin_token or new_token(16)
    app.config["STUDY"] = study
    app.config["STORE"] = store
    # Flask refuses a larger form with 413 too (waitress already does before reading it).
    app.config["MAX_CONTENT_LENGTH"] = MAX_BODY_BYTES
    app.config["MAX_FORM_MEMORY_SIZE"] = MAX_BODY_BYTES
    app.extensions["gazebot_study"] = web
    consent_file = study.root / CONSENT_FILE
    # The ethics board's text replaces ours: paragraphs separated by blank lines.
    consent_text = (
        consent_file.read_text(encoding="utf-8") if consent_file.is_file() else DEFAULT_CONSENT
    )
    consent_paragraphs = [p.strip() for p in consent_text.split("\n\n") if p.strip()]
    n_sessions = {p: len(study.sessions_of(p)) for p in study.participants}
    last_session = {p: max(s.session for s in study.sessions_of(p)) for p in study.participants}
    admin_token = app.config["ADMIN_TOKEN"]
    allowed = tuple(allowed_hosts)

    def visitor() -> str:
        """This browser's random visitor id (a new one, set in the response, if it has none)."""
        if "visitor" not in g:
            cookie = request.cookies.get(VISITOR_COOKIE, "")
            g.visitor = cookie if is_link_token(cookie) else new_token()
            g.new_visitor = g.visitor != cookie
        return g.visitor

    def admin_session() -> str | None:
        """The experimenter's session id of this request (``None``: not signed in). With
        ``local_admin`` a loopback request without one is given a new one (in a cookie), so
        its forms' CSRF tokens are bound to a secret cookie all the same."""
        if "admin_session" not in g:
            cookie = request.cookies.get(ADMIN_COOKIE, "")
            sid = admin_session_of(web.csrf_key, admin_token, cookie, clock(), admin_session_s)
            if sid is None and local_admin and _is_loopback(request.remote_addr):
                sid = g.new_admin_session = new_token()
            g.admin_session = sid
        return g.admin_session

    def form_scope() -> str:
        """The CSRF scope of this request's forms: its participant link, the sign-in form (on
        the sign-in page and its POST) or the experimenter's forms."""
        token = (request.view_args or {}).get("token")
        if isinstance(token, str):
            return f"p:{token}"
        if g.get("login_form") or request.endpoint == "admin_login":
            return "login"
        return "admin"

    def form_csrf() -> str | None:
        """The CSRF token of this request's forms (``None``: an experimenter's form without
        an admin session, which no token opens)."""
        scope = form_scope()
        if scope == "admin":
            sid = admin_session()
            return None if sid is None else web.csrf(scope, sid)
        return web.csrf(scope, visitor())

    @app.context_processor
    def template_globals():
        return {"csrf_token": lambda: form_csrf() or "", "csp_nonce": lambda: g.csp_nonce}

    @app.before_request
    def guard():
        g.csp_nonce = new_token(12)
        # DNS rebinding: a page of evil.example (resolving to this machine) must get nothing.
        if not host_allowed(request.host, allowed):
            abort(
                400,
                description=f"This server does not answer to the host name {request.host!r} "
                "(start it with --allowed-host NAME to add one).",
            )
        if request.method != "POST" or request.url_rule is None:
            return None
        reason = cross_site_reason(request.headers, request.host)
        if reason is not None:
            abort(403, description=f"Refused: {reason}.")
        # Reading the form here is bounded by MAX_CONTENT_LENGTH (413 beyond it).
        given = request.form.get("csrf_token", "")
        expected = form_csrf()
        if expected is None or not tokens_equal(given, expected):
            abort(
                403,
                description="This form has expired: go back, reload the page and retry "
                "(the study's pages need cookies).",
            )
        return None

    @app.after_request
    def headers(resp):
        resp.headers.update(security_headers(getattr(g, "csp_nonce", new_token(12))))
        if g.get("new_visitor"):
            resp.set_cookie(VISITOR_COOKIE, g.visitor, httponly=True, samesite="Lax")
        if g.get("new_admin_session"):
            cookie = admin_cookie(web.csrf_key, admin_token, g.new_admin_session, int(clock()))
            resp.set_cookie(
                ADMIN_COOKIE,
                cookie,
                max_age=int(admin_session_s),
                httponly=True,
                samesite="Strict",
            )
        return resp

    def page(template: str, status: int = 200, **kw: object):
        resp = make_response(render_template(template, **kw), status)
        resp.headers["Cache-Control"] = "no-store"  # a step page must never come from a cache
        return resp

    def participant_of(token: str) -> int:
        participant = by_token.get(token) if is_link_token(token) else None
        if participant is None:
            abort(404, description="No such participant link: check the link you were given.")
        return participant

    def to_page(token: str):
        return redirect(url_for("participant_page", token=token), 303)

    def in_person_page(participant: int):
        return page(
            "message.html",
            409,
            title="Taking part in person",
            message=(
                f"Participant {participant} takes part in person: the experimenter enters the "
                "answers. Please ask the experimenter."
            ),
        )

    def session_page(
        participant: int, token: str, k: int, errors: list[str] | None = None, values=None
    ):
        sessions = study.sessions_of(participant)
        store.mark_shown(participant, k)
        return page(
            "session.html",
            400 if errors else 200,
            link=f"/p/{token}",
            session=k,
            practice=k == PRACTICE,
            position=0 if k == PRACTICE else [s.session for s in sessions].index(k) + 1,
            total=len(sessions),
            caption=attention_caption(study.gaze_mode),
            questions=questions("video"),
            comment_question=COMMENT_QUESTION,
            items=sf.session_items,
            errors=errors or [],
            values=values or {},
        )

    def items_page(token: str, page_id: str, errors=None, values=None):
        return page(
            "page.html",
            400 if errors else 200,
            link=f"/p/{token}",
            page=pages[page_id],
            errors=errors or [],
            values=values or {},
        )

    def end_page(screened_out: bool):
        """The closing page: the completion code (or the screen-out one) shown, or with a
        redirect URL the browser sent there with the code."""
        c = sf.completion
        url = c.url(screened_out)
        if url is not None:
            return redirect(url, 303)
        code = c.screen_out_code if screened_out else c.code
        reached = (
            "Your answer to a check question ended the study here"
            if screened_out
            else "You have completed all the sessions"
        )
        message = f"{reached}; your answers are saved. You can close this page."
        return page("message.html", title="Thank you", message=message, code=code)

    @app.get("/")
    def index():
        code = request.args.get("participant", "").strip()
        if code:
            if not is_link_token(code):
                return page(
                    "index.html", 400, error=f"{code!r} is not a participant code.", value=""
                )
            return redirect(url_for("participant_page", token=code), 303)
        return page("index.html", error=None, value="")

    @app.get("/healthz")
    def healthz():
        return {"ok": True, "participants": len(n_sessions)}

    @app.get("/p/<token>")
    def participant_page(token: str):
        participant = participant_of(token)
        prog = store.progress(participant)
        if prog.mode == "in-person":
            return in_person_page(participant)
        step = current_step(study, store, participant, prog, sf)
        link = f"/p/{token}"
        if step.kind == "consent":
            return page("consent.html", link=link, paragraphs=consent_paragraphs)
        if step.kind == "instructions":
            return page(
                "instructions.html",
                link=link,
                text=instructions(study.gaze_mode),
                total=n_sessions[participant],
            )
        if step.kind == "page":
            return items_page(token, step.page or "")
        if step.kind == "ended":
            return end_page(screened_out=True)
        if step.kind == "done" and (sf.completion.code or sf.completion.redirect_url):
            return end_page(screened_out=False)
        if step.kind == "done":
            return page(
                "message.html",
                title="Thank you",
                message=(
                    f"You have completed all {n_sessions[participant]} sessions; your answers "
                    "are saved. You can close this page."
                ),
            )
        return session_page(participant, token, step.session)

    @app.post("/p/<token>/consent")
    def consent(token: str):
        participant = participant_of(token)
        if request.form.get("consent") != "yes":
            return page(
                "consent.html",
                400,
                link=f"/p/{token}",
                paragraphs=consent_paragraphs,
                error="Please tick the box.",
            )
        if store.progress(participant).mode == "in-person":
            return in_person_page(participant)
        store.give_consent(participant, "video")
        return to_page(token)

    @app.post("/p/<token>/instructions")
    def instructions_read(token: str):
        participant = participant_of(token)
        # The instructions come after the study file's "before" pages: not before they are done.
        if current_step(study, store, participant, None, sf).kind == "instructions":
            store.read_instructions(participant)
        return to_page(token)

    def not_this_step(token: str):
        return page(
            "message.html",
            409,
            title="Not this step yet",
            message="This is not your current step.",
            link=url_for("participant_page", token=token),
        )

    @app.post("/p/<token>/page/<page_id>")
    def submit_page(token: str, page_id: str):
        participant = participant_of(token)
        prog = store.progress(participant)
        if prog.mode == "in-person":
            return in_person_page(participant)
        if page_id in prog.pages:  # a double submit or a resent form: already stored, go on
            return to_page(token)
        step = current_step(study, store, participant, prog, sf)
        if step.kind != "page" or step.page != page_id:
            return not_this_step(token)
        parsed = parse_items(pages[page_id].items, request.form)
        if parsed.errors:
            return items_page(token, page_id, parsed.errors, form_values())
        store.submit_page(participant, page_id, parsed.values, parsed.failed)
        return to_page(token)

    if sf.entry is not None:
        param = sf.entry.param

        @app.get(ENTRY_PATH)
        def entry():
            """The public entry link: the next free plan row for a new external id, the same
            row again for a known one."""
            external = request.args.get(param, "").strip()
            if not EXTERNAL_ID_RE.fullmatch(external):
                return page(
                    "message.html",
                    400,
                    title="Missing participant id",
                    message=f"This link needs your participant id in its {param} parameter: "
                    "open the study from the link the recruiting site gave you.",
                )
            participant = store.assign_entry(external, study.participants)
            if participant is None:
                return page(
                    "message.html",
                    409,
                    title="The study is full",
                    message="Every place in this study is taken. Thank you for your interest.",
                )
            return to_page(web.links[participant])

    def parse_answers(mode: str) -> tuple[dict[str, int], str, list[str]]:
        answers, errors = {}, []
        for k, (q, text) in enumerate(questions(mode).items(), start=1):
            raw = request.form.get(q, "")
            if raw in ("1", "2"):
                answers[q] = int(raw)
            else:
                errors.append(f"Question {k} ({text}) needs an answer: 1st or 2nd.")
        comment = request.form.get("comment", "").strip()[:MAX_COMMENT]
        return answers, comment, errors

    def form_values() -> dict[str, str]:
        return {k: v for k, v in request.form.items() if k != "csrf_token"}

    @app.post("/p/<token>/session/<int:k>")
    def submit(token: str, k: int):
        participant = participant_of(token)
        prog = store.progress(participant)
        if prog.mode == "in-person":
            return in_person_page(participant)
        if k in prog.answered:  # a double submit or a resent form: already stored, go on
            return to_page(token)
        step = current_step(study, store, participant, prog, sf)
        if step.kind != "session" or step.session != k:
            return page(
                "message.html",
                409,
                title="Not this session yet",
                message="This is not your current step.",
                link=url_for("participant_page", token=token),
            )
        answers, comment, errors = parse_answers("video")
        extra = parse_items(sf.session_items, request.form, len(QUESTIONS) + 2)
        if errors or extra.errors:
            return session_page(participant, token, k, errors + extra.errors, form_values())
        store.submit(
            participant,
            k,
            answers,
            comment,
            "video",
            last_session[participant],
            items=extra.values,
            failed=extra.failed,
        )
        return to_page(token)

    @app.get("/p/<token>/video/<int:k>/<int:which>.mp4")
    def video(token: str, k: int, which: int):
        participant = participant_of(token)
        try:
            path = study.video_path(participant, k, which)
        except KeyError:
            abort(404, description="No such video.")
        # conditional=True: Range requests (206 Partial Content), ETag and Last-Modified.
        resp = send_file(path, mimetype="video/mp4", conditional=True, max_age=3600)
        resp.headers["Accept-Ranges"] = "bytes"
        # The file name holds the behavior's name: the study is blind.
        resp.headers.pop("Content-Disposition", None)
        return resp

    # ---- experimenter ----

    def login_page(error: str | None):
        g.login_form = True  # its form gets the visitor's sign-in token, never an admin one
        return page("admin_login.html", 403, error=error)

    def admin_only(view):
        @wraps(view)
        def wrapped(*args, **kwargs):
            if admin_session() is None:
                return login_page(None)
            return view(*args, **kwargs)

        return wrapped

    @app.post("/admin/login")
    def admin_login():
        # The token comes in a form, never in a URL a log or a browser history keeps.
        if not tokens_equal(request.form.get("token", ""), admin_token):
            return login_page("That is not the admin token.")
        # A new random session at each sign-in: a session id planted before it is worth nothing.
        g.new_admin_session = new_token()
        return redirect(url_for("admin"), 303)

    @app.get("/admin")
    @admin_only
    def admin():
        rows = []
        for p in study.participants:
            prog = store.progress(p)
            rows.append(
                {
                    "participant": p,
                    "mode": prog.mode or "",
                    "answered": len([k for k in prog.answered if k != PRACTICE]),
                    "total": n_sessions[p],
                    "step": _step_label(prog, current_step(study, store, p, prog, sf)),
                    "last": _utc(prog.last_activity),
                    "link": request.host_url.rstrip("/") + web.link_path(p),
                }
            )
        return page(
            "admin.html",
            rows=rows,
            started=sum(r["mode"] != "" for r in rows),
            finished=sum(r["step"] == "finished" for r in rows),
            gaze_mode=study.gaze_mode,
        )

    def participant_or_404(participant: int) -> None:
        if participant not in n_sessions:
            abort(404, description=f"Participant {participant} is not in this study's plan.")

    def next_in_person(participant: int) -> Session | None:
        done = set(store.progress(participant).answered)
        return next((s for s in study.sessions_of(participant) if s.session not in done), None)

    def in_person_form(participant: int, errors=None, values=None, status: int = 200):
        prog = store.progress(participant)
        nxt = next_in_person(participant)
        if nxt is not None and prog.mode != "video":
            store.mark_shown(participant, nxt.session)  # the time of the live pair starts
        return page(
            "in_person.html",
            status,
            participant=participant,
            mode=prog.mode,
            session=nxt,
            answered=len(prog.answered),
            total=n_sessions[participant],
            questions=questions("in-person"),
            comment_question=COMMENT_QUESTION,
            familiarity_question=FAMILIARITY_QUESTION,
            ask_familiarity=participant not in store.familiarity(),
            errors=errors or [],
            values=values or {},
        )

    def parse_in_person_extras() -> tuple[int | None, list[float | None], list[str]]:
        """The in-person form's optional fields: the familiarity answer (1-5) and the measured
        reach-start time of each handover (s); empty fields are None."""
        errors: list[str] = []
        fam_raw = request.form.get("familiarity", "").strip()
        fam = None
        if fam_raw:
            if fam_raw in ("1", "2", "3", "4", "5"):
                fam = int(fam_raw)
            else:
                errors.append(f"Familiarity must be 1-5, got {fam_raw[:20]!r}.")
        times: list[float | None] = []
        for k, name in enumerate(("first_reach_start_time", "second_reach_start_time"), 1):
            raw = request.form.get(name, "").strip()
            try:
                value = float(raw) if raw else None
            except ValueError:
                value = float("nan")
            if value is not None and not abs(value) <= MAX_REACH_START_S:
                errors.append(f"Reach-start time of handover {k}: seconds within "
                              f"+-{MAX_REACH_START_S:g}, or empty if not measured; "
                              f"got {raw[:20]!r}.")
                value = None
            times.append(value)
        return fam, times, errors

    @app.get("/admin/in-person/<int:participant>")
    @admin_only
    def in_person(participant: int):
        participant_or_404(participant)
        return in_person_form(participant)

    @app.post("/admin/in-person/<int:participant>")
    @admin_only
    def in_person_submit(participant: int):
        participant_or_404(participant)
        prog = store.progress(participant)
        if prog.mode == "video":
            return in_person_form(participant, ["This participant answers online."], status=409)
        k = request.form.get("session", "")
        if k.isascii() and k.isdigit() and int(k) in prog.answered:
            return redirect(url_for("in_person", participant=participant), 303)
        nxt = next_in_person(participant)
        if nxt is None or not (k.isascii() and k.isdigit()) or int(k) != nxt.session:
            return redirect(url_for("in_person", participant=participant), 303)
        answers, comment, errors = parse_answers("in-person")
        fam, times, extra_errors = parse_in_person_extras()
        if errors or extra_errors:
            return in_person_form(participant, errors + extra_errors, form_values(), status=400)
        now = time.time()
        if prog.mode is None:
            store.give_consent(participant, "in-person", now)
            store.read_instructions(participant, now)
        if fam is not None:
            store.set_familiarity(participant, fam, now)
        if any(t is not None for t in times):
            store.set_reach_starts(participant, nxt.session, times[0], times[1])
        store.submit(
            participant, nxt.session, answers, comment, "in-person", last_session[participant]
        )
        return redirect(url_for("in_person", participant=participant), 303)

    @app.errorhandler(404)
    def not_found(err):
        desc = getattr(err, "description", "")
        known = isinstance(desc, str) and desc.startswith(("Participant", "No such"))
        return page(
            "message.html",
            404,
            title="Not found",
            message=desc if known else "There is no such page: check the link you were given.",
            link=url_for("index"),
        )

    @app.errorhandler(400)
    def bad_request(err):
        return page("message.html", 400, title="Bad request", message=err.description)

    @app.errorhandler(403)
    def forbidden(err):
        return page("message.html", 403, title="Forbidden", message=err.description)

    @app.errorhandler(405)
    def not_allowed(err):
        return page("message.html", 405, title="Not allowed", message="Use the study's pages.")

    @app.errorhandler(413)
    def too_large(err):
        return page(
            "message.html",
            413,
            title="Too large",
            message=f"A form is at most {MAX_BODY_BYTES // 1024} kB: shorten the comment.",
        )

    @app.errorhandler(500)
    def server_error(err):
        return page(
            "message.html",
            500,
            title="Something went wrong",
            message="The server could not handle this request; your saved answers are safe. "
            "Please reload the page.",
        )

    return app
