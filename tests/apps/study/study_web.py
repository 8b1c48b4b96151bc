"""Helpers for the web-study tests: a tiny rendered study (short synthetic clips, no MuJoCo) and
the study server as a real subprocess that a test can SIGKILL and restart."""

from __future__ import annotations

import csv
import functools
import html
import os
import re
import signal
import subprocess
import sys
import time
import urllib.error
import urllib.parse
import urllib.request
from http.cookiejar import CookieJar
from pathlib import Path

from gazebot.apps.study.plan import make_plan
from gazebot.apps.study.render import render_study
from gazebot.apps.study.synthetic import render_synthetic_video
from gazebot.apps.study.video_times import VideoTimes, write_video_times

REPO = Path(__file__).resolve().parents[3]


def render_tiny_study(
    out: Path, behaviors=("face", "hand", "short-face-hand"), participants=6, duration=0.4
):
    """A rendered 6.3-style study (no condition): g (g - 1) sessions per participant, each
    handover a ``duration`` s (0.4 s) synthetic clip at 64x48."""
    plan = make_plan(list(behaviors), condition=None, participants=participants, seed=1)
    fn = functools.partial(timed_synthetic_video, duration=duration)
    render_study(plan, out, fn, 64, 48, 10, workers=1, card_seconds=0.1, progress=False)
    return plan


def reach_start_time_of(behavior: str) -> float:
    """The reach-start time :func:`timed_synthetic_video` reports: distinct per behavior."""
    return round(0.05 * len(behavior) - 0.4, 3)


def timed_synthetic_video(robot, behavior, scene, out_path, **kw):
    """The synthetic clip, with a times sidecar as the MuJoCo renderer writes one."""
    path = render_synthetic_video(robot, behavior, scene, out_path, **kw)
    write_video_times(path, VideoTimes(reach_start_time=reach_start_time_of(behavior)))
    return path


class StudyServer:
    """``python -m gazebot study serve DIR --port 0`` in a subprocess (run in ``cwd``, so
    ``study_dir`` may be relative to it, as the README shows); ``base`` is its URL once it
    listens, ``links[N]`` participant N's link. ``kill()`` sends SIGKILL (no shutdown code
    runs). The admin token comes from the environment, never the command line."""

    def __init__(
        self,
        study_dir: Path,
        token: str = "test-admin-token",
        port: int = 0,
        cwd: Path | None = None,
        args: tuple[str, ...] = (),
    ) -> None:
        self.study_dir = study_dir
        self.token = token
        self.port = port
        self.cwd = cwd
        self.args = args  # more options of `study serve`
        self.proc: subprocess.Popen | None = None
        self.base = ""
        self.links: dict[int, str] = {}

    def start(self, timeout_s: float = 30.0) -> StudyServer:
        """Start the server (on the port of the last start, if any) and wait until it listens."""
        env = {
            **os.environ,
            "PYTHONPATH": str(REPO),
            "PYTHONUNBUFFERED": "1",
            "GAZEBOT_STUDY_ADMIN_TOKEN": self.token,
        }
        self.proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "gazebot",
                "study",
                "serve",
                str(self.study_dir),
                "--port",
                str(self.port),
                *self.args,
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=env,
            cwd=self.cwd,
        )
        deadline = time.monotonic() + timeout_s
        lines = []
        assert self.proc.stdout is not None
        while time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            lines.append(line)
            m = re.search(r"at (http://\S+)/p/TOKEN", line)
            if m:
                self.base = m.group(1)
                self.port = int(self.base.rsplit(":", 1)[1])
                self.proc.stdout.readline()  # the experimenter line
                self.links = read_links(Path(self.cwd or ".") / self.study_dir)
                return self
        self.stop()
        raise RuntimeError("study server did not start:\n" + "".join(lines))

    def kill(self) -> None:
        """SIGKILL, as a crash or the OOM killer would."""
        if self.proc and self.proc.poll() is None:
            os.kill(self.proc.pid, signal.SIGKILL)
            self.proc.wait(timeout=10)

    def stop(self) -> None:
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.kill()
        if self.proc and self.proc.stdout:
            self.proc.stdout.close()

    def __enter__(self) -> StudyServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


class _NoRedirect(urllib.request.HTTPRedirectHandler):
    def redirect_request(self, *args, **kwargs):  # noqa: ANN002, ANN003
        return None


_opener = urllib.request.build_opener(_NoRedirect)


def http(
    method: str,
    url: str,
    data: dict | None = None,
    headers: dict | None = None,
    opener: urllib.request.OpenerDirector | None = None,
):
    """(status, headers, body) of one request; redirects are not followed."""
    body = urllib.parse.urlencode(data).encode() if data is not None else None
    req = urllib.request.Request(url, data=body, method=method, headers=headers or {})
    try:
        with (opener or _opener).open(req, timeout=30) as resp:
            return resp.status, dict(resp.headers), resp.read()
    except urllib.error.HTTPError as err:
        return err.code, dict(err.headers), err.read()


class Visitor:
    """A browser's part in a request, over urllib: it keeps the server's cookies and sends the
    ``Origin`` of the page on its POSTs (as a browser does on a form of the site, with
    ``Referrer-Policy: same-origin``). ``request`` answers as :func:`http` does."""

    def __init__(self, base: str) -> None:
        self.origin = base
        self.jar = CookieJar()
        self._opener = urllib.request.build_opener(
            _NoRedirect, urllib.request.HTTPCookieProcessor(self.jar)
        )

    def request(self, method: str, url: str, data: dict | None = None):
        headers = {"Origin": self.origin} if method == "POST" else {}
        return http(method, url, data, headers, opener=self._opener)

    def form_token(self, url: str) -> str:
        """The CSRF token of the form on the page at ``url`` (fetched now)."""
        status, _, body = self.request("GET", url)
        assert status == 200, status
        return form_token(body)


def read_links(study_dir: Path) -> dict[int, str]:
    """``participant-links.csv`` that ``study serve`` wrote: participant -> URL."""
    with (study_dir / "participant-links.csv").open(newline="") as fh:
        return {int(r["participant"]): r["url"] for r in csv.DictReader(fh)}


def form_token(page: bytes | str) -> str:
    """The CSRF token of a page's form (as a browser would send it back)."""
    text = page.decode() if isinstance(page, bytes) else page
    m = re.search(r'name="csrf_token" value="([^"]+)"', text)
    assert m, "the page has no form with a CSRF token"
    return html.unescape(m.group(1))
