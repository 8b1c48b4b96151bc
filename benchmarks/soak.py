"""The bus soak (issue 30): everything a lab runs at once, on one machine, for ten minutes.

``python -m benchmarks.soak`` (``make soak``) starts a router, a recording engine
(``gazebot run --record``), a witness recorder of its own (a second, never-killed recorder on the
same bus), the simulator restarted ``--sims`` times (one handover each) and a study server with
``--participants`` participants going through the study in threads; at a random moment during
the last simulated handover it SIGKILLs the recording engine. Then it prints:

- handovers: the engine's ``reach_started`` and ``handover_done`` events against the simulator
  runs that completed a handover (phantoms: reaches beyond one per run);
- lost events: robot and engine events the witness saw that the engine's own recording lacks,
  and simulator runs whose handover is not whole (reach, transfer, retreat, done, in order);
- the engine's resident memory over the last ``--rss-window`` s before the kill (growth; 5 MB
  or more fails the soak);
- what the SIGKILLed recording holds: ``mcap``'s default reader on it (or on the output of
  ``gazebot mcap recover``), and every message the witness received more than 1 s before the kill
  that is missing from it;
- the study: participants done, requests, slowest answer.

A soak is a measurement, not a test (it takes ten minutes and a quiet machine); the figures go
into the issue notes and ``docs/bus.md``.
"""

from __future__ import annotations

import argparse
import http.cookiejar
import json
import os
import random
import re
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.parse
import urllib.request
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
NAMESPACE = "/gazebot"
EVENTS = f"{NAMESPACE}/handover/events"
ROBOT_EVENTS = f"{NAMESPACE}/robot/events"
#: The recorder flushes once a second; what the witness received this long before the kill must
#: be in the killed file (the flush period plus delivery).
KILL_ALLOWANCE_S = 1.0
RSS_GROWTH_MAX_MB = 5.0  # the bar on the engine's growth over the last window


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _gazebot(*args: str, log: Path) -> subprocess.Popen:
    fh = log.open("w")
    return subprocess.Popen([sys.executable, "-m", "gazebot", *args], stdout=fh,
                            stderr=subprocess.STDOUT, cwd=REPO,
                            env={**os.environ, "PYTHONPATH": str(REPO)})


def _rss_mb(pid: int) -> float | None:
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return None
    m = re.search(r"VmRSS:\s+(\d+) kB", text)
    return int(m.group(1)) / 1024 if m else None


# ---------------------------------------------------------------- the study load


@dataclass
class StudyLoad:
    """Participants going through a served study, each in a thread, spread over ``span`` s."""

    base_links: dict[int, str]
    origin: str
    span: float
    latencies: list[float] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    done: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)

    def _request(self, opener: urllib.request.OpenerDirector, method: str, url: str,
                 data: dict | None = None) -> tuple[int, bytes]:
        body = urllib.parse.urlencode(data).encode() if data is not None else None
        headers = {"Origin": self.origin} if method == "POST" else {}
        req = urllib.request.Request(url, data=body, method=method, headers=headers)
        t0 = time.monotonic()
        try:
            with opener.open(req, timeout=30) as resp:
                status, payload = resp.status, resp.read()
        except urllib.error.HTTPError as err:
            status, payload = err.code, err.read()
        with self.lock:
            self.latencies.append(time.monotonic() - t0)
        return status, payload

    def participant(self, pid: int, link: str, sessions: int, rng: random.Random) -> None:
        class NoRedirect(urllib.request.HTTPRedirectHandler):
            def redirect_request(self, *args, **kwargs):  # noqa: ANN002, ANN003
                return None

        opener = urllib.request.build_opener(
            NoRedirect, urllib.request.HTTPCookieProcessor(http.cookiejar.CookieJar()))
        time.sleep(rng.uniform(0, self.span / 2))
        try:
            status, page = self._request(opener, "GET", link)
            token = re.search(rb'name="csrf_token" value="([^"]+)"', page)
            if status != 200 or token is None:
                raise RuntimeError(f"first page: status {status}")
            csrf = token.group(1).decode()
            steps = [("consent", {"consent": "yes"}), ("instructions", {})]
            steps += [(f"session/{k}", {f"q{i}": str(rng.choice((1, 2))) for i in range(1, 6)})
                      for k in range(sessions)]
            for path, data in steps:
                time.sleep(rng.uniform(0.5, 2 * self.span / (2 * len(steps))))
                status, _ = self._request(opener, "POST", f"{link}/{path}",
                                          {**data, "csrf_token": csrf})
                if status != 303:
                    raise RuntimeError(f"POST {path}: status {status}")
            with self.lock:
                self.done += 1
        except Exception as exc:  # noqa: BLE001 - counted and reported: the soak goes on
            with self.lock:
                self.errors.append(f"participant {pid}: {exc}")


def _render_study(out: Path, participants: int) -> int:
    """A small study (three behaviors, short synthetic clips) for at least ``participants``;
    its sessions per participant, practice included."""
    from gazebot.apps.study.plan import make_plan
    from gazebot.apps.study.render import render_study
    from gazebot.apps.study.synthetic import render_synthetic_video

    behaviors = ["face", "hand", "short-face-hand"]
    block = len(behaviors) * (len(behaviors) - 1)  # the plan counterbalances whole blocks
    plan = make_plan(behaviors, condition=None, participants=-(-participants // block) * block,
                     seed=1)

    def clip(robot, behavior, scene, out_path, **kw):  # noqa: ANN001, ANN003
        return render_synthetic_video(robot, behavior, scene, out_path, duration=0.4, **kw)

    render_study(plan, out, clip, 64, 48, 10, workers=1, card_seconds=0.1, progress=False)
    return len(behaviors) * (len(behaviors) - 1) + 1


# ---------------------------------------------------------------- reading the recordings


def _messages(path: Path) -> list[tuple[str, float, bytes]]:
    """(topic, log time in s, CDR bytes) of every message ``mcap``'s default reader reads."""
    from mcap.reader import make_reader

    with path.open("rb") as f:
        return [(c.topic, m.log_time * 1e-9, bytes(m.data))
                for _, c, m in make_reader(f).iter_messages(log_time_order=False)]


def _events(messages: list[tuple[str, float, bytes]], topic: str) -> list[tuple[float, str, str]]:
    from gazebot.io.ros2.typestore import typestore

    store = typestore()
    out = []
    for t, stamp, data in messages:
        if t == topic:
            msg = store.deserialize_cdr(data, "gazebot_msgs/msg/HandoverEvent")
            out.append((stamp, msg.category, msg.kind))
    return sorted(out)


def _read_killed(path: Path, log: Path) -> tuple[list[tuple[str, float, bytes]], str]:
    try:
        return _messages(path), "read directly"
    except Exception as exc:  # noqa: BLE001 - a file cut short: what `mcap recover` is for
        first = f"{type(exc).__name__}: {exc}"
    recovered = path.with_name(path.stem + "-recovered.mcap")
    proc = _gazebot("mcap", "recover", str(path), "-o", str(recovered), log=log)
    proc.wait(timeout=300)
    return _messages(recovered), f"after `gazebot mcap recover` (direct read: {first})"


# ---------------------------------------------------------------- the soak


def soak(args: argparse.Namespace) -> dict:
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    for old in out.glob("*.mcap"):
        old.unlink()
    rng = random.Random(args.seed)
    port = _free_port()
    bus = ["--connect", f"tcp/127.0.0.1:{port}", "--listen", "tcp/127.0.0.1:0"]
    total = args.duration + 120
    procs: list[subprocess.Popen] = []
    result: dict = {"duration_s": args.duration, "sims": args.sims,
                    "participants": args.participants}

    shutil.rmtree(out / "study", ignore_errors=True)  # a fresh study: nobody has answered yet
    sessions = _render_study(out / "study", args.participants)
    router = _gazebot("router", "--listen", f"tcp/127.0.0.1:{port}", "--duration", str(total),
                      log=out / "router.log")
    procs.append(router)
    time.sleep(2)

    import zenoh  # noqa: F401 - the witness's session

    from gazebot.io.drivers.recorder import BusRecorder
    from gazebot.io.drivers.rmw.names import Names
    from gazebot.io.drivers.session import BusConfig, open_session

    witness_session = open_session(BusConfig(names=Names(), listen=("tcp/127.0.0.1:0",),
                                             connect=(f"tcp/127.0.0.1:{port}",)))
    witness = BusRecorder(witness_session, Names(), out / "witness.mcap")

    engine_file = out / "engine.mcap"
    engine = _gazebot("run", "--robot", "sawyer", *bus, "--record", str(engine_file),
                      "--duration", str(total), log=out / "engine.log")
    procs.append(engine)
    study_env = {**os.environ, "PYTHONPATH": str(REPO),
                 "GAZEBOT_STUDY_ADMIN_TOKEN": "soak-admin-token"}
    study_port = _free_port()
    server = subprocess.Popen(
        [sys.executable, "-m", "gazebot", "study", "serve", str(out / "study"), "--port",
         str(study_port)], stdout=(out / "study.log").open("w"), stderr=subprocess.STDOUT,
        cwd=REPO, env=study_env)
    procs.append(server)
    try:
        import csv

        deadline = time.monotonic() + 60
        while "/p/TOKEN" not in (out / "study.log").read_text():
            if server.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError("the study server did not start: "
                                   + (out / "study.log").read_text())
            time.sleep(0.2)

        with (out / "study" / "participant-links.csv").open(newline="") as fh:
            links = {int(r["participant"]): r["url"] for r in csv.DictReader(fh)}
        load = StudyLoad(links, f"http://127.0.0.1:{study_port}", args.duration)
        threads = [threading.Thread(target=load.participant,
                                    args=(pid, link, sessions, random.Random(pid)), daemon=True)
                   for pid, link in sorted(links.items())[: args.participants]]
        t0 = time.monotonic()
        for t in threads:
            t.start()

        rss: list[tuple[float, float]] = []
        stop_rss = threading.Event()

        def sample_rss() -> None:
            while not stop_rss.wait(2.0):
                value = _rss_mb(engine.pid)
                if value is not None:
                    rss.append((time.monotonic() - t0, value))

        sampler = threading.Thread(target=sample_rss, daemon=True)
        sampler.start()

        period = args.duration / args.sims
        sims: list[dict] = []
        kill_at = kill_mono = 0.0
        for k in range(args.sims):
            while time.monotonic() - t0 < k * period:
                time.sleep(0.1)
            last = k == args.sims - 1
            started = time.monotonic()
            sim = _gazebot("sim", "--robot", "sawyer", "--headless", *bus, "--seed", str(k),
                           "--duration", str(args.sim_seconds), "--json",
                           log=out / f"sim-{k}.log")
            if last:  # the kill, at a random moment of the last handover
                time.sleep(rng.uniform(4.0, args.sim_seconds))
                kill_at = time.time()
                kill_mono = time.monotonic() - t0
                engine.send_signal(signal.SIGKILL)
                engine.wait(timeout=30)
            sim.wait(timeout=args.sim_seconds + 90)
            summary_line = (out / f"sim-{k}.log").read_text().strip().splitlines()[-1:]
            try:
                summary = json.loads(summary_line[0]) if summary_line else {}
            except json.JSONDecodeError:
                summary = {}
            sims.append({"run": k, "start": started - t0, "end": time.monotonic() - t0,
                         "rc": sim.returncode,
                         "handover_done": bool(summary.get("handover_done"))})
        stop_rss.set()
        for t in threads:
            t.join(timeout=args.duration)
    finally:
        witness.close()
        witness_session.close()
        for p in procs:
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()

    # Handovers and phantoms: one reach per simulator run, never more (the last run's are
    # counted up to the kill).
    seen = _messages(out / "witness.mcap")
    events = _events(seen, EVENTS)
    phase = Counter(kind for _, cat, kind in events if cat == "phase")
    done_runs = sum(s["handover_done"] for s in sims[:-1])
    result["sim_runs"] = {"completed_handover": done_runs + sims[-1]["handover_done"],
                          "failed": [s for s in sims if s["rc"] not in (0, None)]}
    before_kill = [e for e in events if e[0] < kill_at]
    # Reaches per run window, from the witness's log times (wall clock).
    wall0 = kill_at - kill_mono
    reaches_per_run = []
    for s in sims:
        lo, hi = wall0 + s["start"], wall0 + s["end"]
        reaches_per_run.append(sum(1 for t, c, k in before_kill
                                   if c == "phase" and k == "reach_started" and lo <= t < hi))
    result["engine_events"] = dict(phase)
    result["reaches_per_run"] = reaches_per_run
    result["phantom_handovers"] = sum(max(0, n - 1) for n in reaches_per_run) + sum(
        1 for t, c, k in before_kill if c == "phase" and k == "reach_started"
        and not any(wall0 + s["start"] <= t < wall0 + s["end"] for s in sims))
    result["handovers_done"] = phase.get("handover_done", 0)

    # Each completed run's handover, whole: reach, transfer, retreat, done, in that order.
    whole = ["reach_started", "transfer_started", "retreat_started", "handover_done"]
    broken = []
    for run in sims[:-1]:
        lo, hi = wall0 + run["start"], wall0 + run["end"]
        kinds = [k for t, c, k in events if c == "phase" and k in whole and lo <= t < hi]
        if kinds != whole:
            broken.append({"run": run["run"], "phases": kinds})
    result["runs_without_a_whole_handover"] = broken
    result["robot_events"] = sum(1 for t, _, _ in _events(seen, ROBOT_EVENTS) if t < kill_at)

    # The killed recording against the witness.
    killed, how = _read_killed(engine_file, out / "recover.log")
    have = Counter((t, d) for t, _, d in killed)
    start = min(t for _, t, _ in killed) + 5.0  # both recorders up
    due = Counter((t, d) for t, s, d in seen if start <= s < kill_at - KILL_ALLOWANCE_S)
    missing = due - have
    result["killed_recording"] = {"read": how, "messages": len(killed),
                                  "due": sum(due.values()), "missing": sum(missing.values()),
                                  "missing_topics": dict(Counter(t for t, _ in missing.elements()))}
    # Lost events: events (the engine's and the robot's) missing from the engine's recording.
    result["events_lost"] = sum(1 for t, _ in missing.elements() if t in (EVENTS, ROBOT_EVENTS))

    # Memory over the last window before the kill.
    window = [(t, v) for t, v in rss if kill_mono - args.rss_window <= t < kill_mono]
    if len(window) >= 6:
        head = statistics.median(v for _, v in window[:3])
        tail = statistics.median(v for _, v in window[-3:])
        result["engine_rss_mb"] = {"window_s": args.rss_window, "start": round(head, 1),
                                   "end": round(tail, 1), "growth": round(tail - head, 2),
                                   "max": round(max(v for _, v in window), 1),
                                   "first_sample": round(rss[0][1], 1) if rss else None}
    lat = sorted(load.latencies)
    result["study"] = {"participants_done": load.done, "errors": load.errors[:5],
                       "requests": len(lat),
                       "median_s": round(statistics.median(lat), 4) if lat else None,
                       "slowest_s": round(lat[-1], 4) if lat else None}
    return result


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.soak", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--duration", type=float, default=600.0, help="seconds (default 600)")
    parser.add_argument("--sims", type=int, default=29, help="simulator runs (default 29)")
    parser.add_argument("--sim-seconds", type=float, default=16.0,
                        help="simulated seconds per run (default 16: one handover)")
    parser.add_argument("--participants", type=int, default=50)
    parser.add_argument("--rss-window", type=float, default=300.0,
                        help="seconds before the kill over which memory growth is measured")
    parser.add_argument("--seed", type=int, default=0, help="seed of the kill moment")
    parser.add_argument("--out", type=Path, default=REPO / "out" / "soak")
    args = parser.parse_args(argv)
    result = soak(args)
    print(json.dumps(result, indent=2))
    rss = result.get("engine_rss_mb")
    bad = (result["phantom_handovers"] or result["events_lost"]
           or result["runs_without_a_whole_handover"]
           or result["killed_recording"]["missing"]
           or result["study"]["participants_done"] < args.participants
           or rss is None or rss["growth"] >= RSS_GROWTH_MAX_MB)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
