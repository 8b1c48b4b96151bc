"""The study: Bradley-Terry fit time (gazebot's Hunter MM, vectorised on the win matrix, against
``choix`` on the same comparisons), and the web study's answer submissions per second (``gazebot
study serve`` on loopback: waitress + Flask + a committed SQLite transaction per answer) against a
bare waitress app that parses the same form and commits it to SQLite with the same durability
(and, as a floor, one that stores nothing), served and driven the same way; plus the page weight
of a session page."""

from __future__ import annotations

import csv
import html
import http.client
import itertools
import os
import re
import subprocess
import sys
import tempfile
import threading
import time
import urllib.parse
from dataclasses import dataclass
from http.cookies import SimpleCookie
from pathlib import Path

import numpy as np

from benchmarks.common import Result, median_time
from gazebot.apps.study.web.app import VISITOR_COOKIE

# Seed Table 6.1, likability (video study; rows Face, Hand, L-FH, S-FH; averaged, fractional).
TABLE_6_1_LIKABILITY = np.array(
    [[0, 6.75, 2.75, 2.25], [17.25, 0, 3.5, 4.75], [21.25, 20.5, 0, 8], [21.75, 19.25, 16, 0]]
)
TOL = 1e-10


def _comparisons(g: int, participants: int, seed: int = 0) -> list[tuple[int, int]]:
    """Every participant compares every ordered pair once; winner drawn from a BT model."""
    rng = np.random.default_rng(seed)
    s = rng.uniform(0.3, 3.0, g)
    data = []
    for _ in range(participants):
        for i, j in itertools.permutations(range(g), 2):
            data.append((i, j) if rng.random() < s[i] / (s[i] + s[j]) else (j, i))
    return data


# The peers: the same server (waitress, same threads) with an app that parses the answer form
# and redirects. The fair peer also stores each answer as gazebot does, durably: one committed
# SQLite transaction per answer (WAL, synchronous=FULL, a connection per request, the primary
# key keeping a resend once), but without Flask, without the cookie, Origin and CSRF checks and
# without reading the participant's place. With no database argument it stores nothing: the
# floor of HTTP and the server alone. Both get the very requests gazebot gets (same paths,
# cookies, Origin header and form with its CSRF token).
_BARE_SERVER = """
import sqlite3, sys, threading, urllib.parse
from waitress import create_server
DB = sys.argv[1] if len(sys.argv) > 1 else None
LOCK = threading.Lock()
def connect():
    con = sqlite3.connect(DB, timeout=10, isolation_level=None)
    con.execute("PRAGMA synchronous=FULL")
    return con
if DB:
    con = connect()
    con.execute("PRAGMA journal_mode=WAL")
    con.execute("CREATE TABLE IF NOT EXISTS answers (participant TEXT, session INTEGER, "
                "q1, q2, q3, q4, q5, comment, submitted_at REAL DEFAULT (julianday('now')), "
                "PRIMARY KEY (participant, session))")
    con.close()
def app(environ, start_response):
    n = int(environ.get("CONTENT_LENGTH") or 0)
    form = urllib.parse.parse_qs(environ["wsgi.input"].read(n).decode(), keep_blank_values=True)
    ok = all(form.get(q) in (["1"], ["2"]) for q in ("q1", "q2", "q3", "q4", "q5"))
    _, _, token, _, k = environ["PATH_INFO"].split("/")
    if ok and DB:
        with LOCK:
            con = connect()
            try:
                con.execute("BEGIN IMMEDIATE")
                con.execute("INSERT INTO answers (participant, session, q1, q2, q3, q4, q5, "
                            "comment) VALUES (?, ?, ?, ?, ?, ?, ?, ?) ON CONFLICT DO NOTHING",
                            (token, int(k), *(int(form[q][0]) for q in
                             ("q1", "q2", "q3", "q4", "q5")), form["comment"][0]))
                con.execute("COMMIT")
            finally:
                con.close()
    start_response("303 See Other" if ok else "400 Bad Request",
                   [("Location", "/p/" + token), ("Content-Length", "0")])
    return [b""]
server = create_server(app, host="127.0.0.1", port=0, threads=4)
print(f"serving at http://127.0.0.1:{server.effective_port}/p/TOKEN", flush=True)
server.run()
"""
ANSWERS = {"q1": 1, "q2": 2, "q3": 1, "q4": 2, "q5": 1, "comment": ""}
BATCH = 120  # submissions per timed batch
BATCHES = 5
ADMIN_TOKEN = "benchmark-admin-token"  # from the environment, as the server wants it


@dataclass(frozen=True)
class Participant:
    """What a participant's browser holds once it opened its link: the link path, its visitor
    cookie and the CSRF token of its forms (bound to that cookie and that link)."""

    link: str
    cookie: str
    csrf: str


def _start(cmd: list[str]) -> tuple[subprocess.Popen, int]:
    env = {
        **os.environ,
        "PYTHONPATH": str(Path(__file__).resolve().parents[1]),
        "GAZEBOT_STUDY_ADMIN_TOKEN": ADMIN_TOKEN,
    }
    proc = subprocess.Popen(
        cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env
    )
    line = ""
    for _ in range(20):
        line = proc.stdout.readline()
        m = re.search(r"at http://127\.0\.0\.1:(\d+)/p/TOKEN", line)
        if m:
            return proc, int(m.group(1))
    proc.kill()
    raise RuntimeError(f"server did not start: {line}")


def _read_links(study_dir: Path) -> dict[int, str]:
    """Participant -> link path, from the ``participant-links.csv`` that ``study serve`` wrote."""
    with (study_dir / "participant-links.csv").open(newline="") as fh:
        return {int(r["participant"]): urllib.parse.urlsplit(r["url"]).path
                for r in csv.DictReader(fh)}


def _open_link(port: int, link: str) -> tuple[Participant, bytes]:
    """A participant's first visit, as a browser makes it: GET the link, keep the visitor cookie
    the server sets and the CSRF token of the page's form."""
    con = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    con.request("GET", link)
    resp = con.getresponse()
    page = resp.read()
    con.close()
    if resp.status != 200:
        raise RuntimeError(f"GET {link}: HTTP {resp.status}")
    cookie = SimpleCookie(resp.getheader("Set-Cookie", ""))
    if VISITOR_COOKIE not in cookie:
        raise RuntimeError(f"GET {link}: no {VISITOR_COOKIE} cookie set")
    m = re.search(rb'name="csrf_token" value="([^"]+)"', page)
    if m is None:
        raise RuntimeError(f"GET {link}: the page has no form with a CSRF token")
    visitor = f"{VISITOR_COOKIE}={cookie[VISITOR_COOKIE].value}"
    return Participant(link, visitor, html.unescape(m.group(1).decode())), page


def _submit(port: int, posts: list[tuple[Participant, int]], clients: int) -> float:
    """Seconds to POST the answers of every (participant, session), over ``clients`` keep-alive
    connections, each request with the participant's cookie, the page's ``Origin`` and the
    form's CSRF token (what a browser sends)."""
    chunks = [posts[k::clients] for k in range(clients)]
    origin = f"http://127.0.0.1:{port}"
    bodies = {}
    for who, _ in posts:
        if who.link not in bodies:
            bodies[who.link] = urllib.parse.urlencode({**ANSWERS, "csrf_token": who.csrf})

    def worker(chunk: list[tuple[Participant, int]]) -> None:
        con = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
        for who, k in chunk:
            path = f"{who.link}/session/{k}"
            headers = {
                "Content-Type": "application/x-www-form-urlencoded",
                "Cookie": who.cookie,
                "Origin": origin,
            }
            con.request("POST", path, bodies[who.link], headers)
            resp = con.getresponse()
            resp.read()
            if resp.status != 303:
                raise RuntimeError(f"POST {path}: HTTP {resp.status}")
        con.close()

    threads = [threading.Thread(target=worker, args=(c,)) for c in chunks]
    t0 = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return time.perf_counter() - t0


def _web_results() -> list[Result]:
    import functools
    import statistics

    from gazebot.apps.study.folder import load_study
    from gazebot.apps.study.plan import make_plan
    from gazebot.apps.study.render import render_study
    from gazebot.apps.study.synthetic import render_synthetic_video

    results = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp) / "study"
        behaviors = ["face", "hand", "short-face-hand", "long-face-hand"]
        clients_list = (1, 4)
        need = BATCH * (BATCHES + 1) * len(clients_list)
        participants = 12 * -(-need // 12 // 12)
        plan = make_plan(behaviors, None, participants, seed=0)
        fn = functools.partial(render_synthetic_video, duration=0.2)
        render_study(plan, root, fn, 64, 48, 10, workers=1, card_seconds=0.1, progress=False)
        study = load_study(root)
        store = study.store()
        for p in study.participants:  # everyone past consent and practice: only sessions left
            store.give_consent(p)
            store.read_instructions(p)
            store.submit(p, 0, {f"q{k}": 1 for k in range(1, 6)})
        ours, port = _start(
            [sys.executable, "-m", "gazebot", "study", "serve", str(root), "--port", "0"]
        )
        peer_db = Path(tmp) / "peer.sqlite"
        durable, durable_port = _start([sys.executable, "-c", _BARE_SERVER, str(peer_db)])
        bare, bare_port = _start([sys.executable, "-c", _BARE_SERVER])
        try:
            # Every participant opens their link once (untimed): cookie and form token.
            links = _read_links(root)
            visits = {p: _open_link(port, links[p]) for p in study.participants}
            who = {p: v[0] for p, v in visits.items()}
            page = visits[study.participants[-1]][1]
            # Answers in plan order per participant: each request is the current step.
            posts = [
                (who[s.participant], s.session)
                for s in sorted(study.plan, key=lambda s: (s.session, s.participant))
            ]
            pos = 0
            for clients in clients_list:
                rates, peer_rates, floor_rates = [], [], []
                for b in range(BATCHES + 1):  # the first batch warms up
                    batch = posts[pos : pos + BATCH]
                    pos += BATCH
                    t_ours = _submit(port, batch, clients)
                    t_peer = _submit(durable_port, batch, clients)
                    t_floor = _submit(bare_port, batch, clients)
                    if b:
                        rates.append(BATCH / t_ours)
                        peer_rates.append(BATCH / t_peer)
                        floor_rates.append(BATCH / t_floor)
                results.append(
                    Result(
                        f"answer submissions, {clients} keep-alive client(s), loopback",
                        statistics.median(rates),
                        statistics.median(peer_rates),
                        "req/s",
                        "bare waitress app committing the same answer to SQLite, same pragmas",
                        higher_is_better=True,
                        note="each answer a committed SQLite transaction (WAL, synchronous=FULL), "
                        "with the visitor cookie, Origin and CSRF checks; storing nothing: "
                        f"{statistics.median(floor_rates):.0f} req/s",
                    )
                )
        finally:
            for proc in (ours, durable, bare):
                proc.terminate()
                proc.wait(timeout=10)
        stored = len(store.answers())
        import sqlite3

        with sqlite3.connect(peer_db) as con:
            peer_stored = con.execute("SELECT COUNT(*) FROM answers").fetchone()[0]
        if stored != pos or peer_stored != pos:
            raise RuntimeError(f"{pos} answers sent, {stored} stored, {peer_stored} by the peer")
        results.append(
            Result(
                "session page weight (HTML, inline CSS and JS; videos extra)",
                len(page) / 1024,
                None,
                "kB",
            )
        )
    return results


def run() -> list[Result]:
    import choix

    from gazebot.apps.study.bradley_terry import fit_bradley_terry

    def probs(theta: np.ndarray) -> np.ndarray:
        e = np.exp(theta - theta.max())
        return e / e.sum()

    results = []
    w = TABLE_6_1_LIKABILITY
    diff = np.abs(fit_bradley_terry(w, tol=TOL).p - probs(choix.ilsr_pairwise_dense(w, tol=TOL)))
    ours = median_time(lambda: fit_bradley_terry(w, tol=TOL), repeat=15, number=20)
    peer = median_time(
        lambda: choix.ilsr_pairwise_dense(w, tol=TOL, max_iter=1000), repeat=15, number=20
    )
    results.append(
        Result(
            "BT fit, seed Table 6.1 likability (4 conditions, fractional)",
            ours * 1e3,
            peer * 1e3,
            "ms",
            "choix.ilsr_pairwise_dense",
            note=f"tol {TOL:g}, max |dP| {diff.max():.1e}",
        )
    )

    for g, n in ((3, 24), (10, 24)):
        data = _comparisons(g, n)
        arr = np.asarray(data)

        def ours_fn(arr=arr, g=g):
            wins = np.zeros((g, g))
            np.add.at(wins, (arr[:, 0], arr[:, 1]), 1.0)
            return fit_bradley_terry(wins, tol=TOL)

        ours = median_time(ours_fn, repeat=9, number=5)
        mm = median_time(
            lambda data=data, g=g: choix.mm_pairwise(g, data, tol=TOL, max_iter=100_000),
            repeat=9,
            number=5,
        )
        ilsr = median_time(
            lambda data=data, g=g: choix.ilsr_pairwise(g, data, tol=TOL, max_iter=1000),
            repeat=9,
            number=5,
        )
        p_ours = ours_fn().p
        d_mm = np.abs(p_ours - probs(choix.mm_pairwise(g, data, tol=TOL, max_iter=100_000))).max()
        d_ilsr = np.abs(p_ours - probs(choix.ilsr_pairwise(g, data, tol=TOL))).max()
        label = f"BT fit, {g} conditions x {n} participants ({len(data)} comparisons)"
        results.append(
            Result(
                label,
                ours * 1e3,
                mm * 1e3,
                "ms",
                "choix.mm_pairwise",
                note=f"tol {TOL:g}, max |dP| {d_mm:.1e}",
            )
        )
        results.append(
            Result(
                label,
                ours * 1e3,
                ilsr * 1e3,
                "ms",
                "choix.ilsr_pairwise",
                note=f"tol {TOL:g}, max |dP| {d_ilsr:.1e}",
            )
        )
    return results + _web_results()
