"""``gazebot study serve``: the study's Flask app on waitress, a production WSGI server.

Slow clients. waitress reads each request whole in its event loop before a worker thread sees
it, so a connection that sends half a request (a "slowloris") holds no thread, only a socket.
What it can exhaust is waitress's ``connection_limit`` (100 by default): with 100 such
connections open waitress stops accepting, and every participant waits. So the server takes
:class:`ConnectionLimits`: many more connections than one attacker's worth (1000 by default,
watched with ``poll()``, since ``select()`` cannot watch a socket numbered 1024 or above), and
a connection that sends nothing for ``channel_timeout_s`` is closed (checked every
``cleanup_interval_s``). A determined attacker with thousands of connections still needs a
reverse proxy in front (nginx's ``client_header_timeout`` and ``limit_conn``); see
``docs/study-file.md``.
"""

from __future__ import annotations

import csv
import ipaddress
import logging
import os
import re
import resource
import socket
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from gazebot.apps.study.folder import load_study
from gazebot.apps.study.web.app import create_app
from gazebot.apps.study.web.security import (
    ADMIN_TOKEN_ENV,
    LOOPBACK_HOSTS,
    MAX_BODY_BYTES,
    new_token,
    rate_limit_logs,
)

log = logging.getLogger(__name__)

LINKS_FILE = "participant-links.csv"
ADMIN_TOKEN_FILE = "admin-token"  # written (mode 0600) when no token is given


def base_url(host: str, port: int) -> str:
    """The address to print for a server on ``host``: a wildcard address (all interfaces) is
    not one a browser can open, so the machine's name stands for it."""
    if host in ("", "0.0.0.0", "::"):
        host = socket.gethostname()
    shown = f"[{host}]" if ":" in host else host
    return f"http://{shown}:{port}"


_LABEL = r"[A-Za-z0-9][A-Za-z0-9-]{0,62}"
_HOST_NAME_RE = re.compile(rf"{_LABEL}(\.{_LABEL})*\.?")


def check_host_name(name: str) -> str:
    """``name`` if it is a host name or an IP address (what ``--allowed-host`` takes), else
    ``ValueError`` saying what was expected."""
    bare = name.strip("[]")
    try:
        ipaddress.ip_address(bare)
        return bare
    except ValueError:
        pass  # not an IP address: it may still be a host name
    if len(name) <= 253 and _HOST_NAME_RE.fullmatch(name):
        return name
    raise ValueError(
        f"--allowed-host: {name!r} is not a host name (expected a name such as "
        "study.lab.example or an IP address: no scheme, port or path)"
    )


def served_host_names(host: str, extra: tuple[str, ...] = ()) -> tuple[str, ...]:
    """The names a request's ``Host`` may give for a server bound to ``host``: the loopback
    names, the bound name (for a wildcard address the machine's name and full name, as
    :func:`base_url` prints it), and ``extra`` (``--allowed-host``: a reverse proxy's or a DNS
    name of this machine). IP addresses are always accepted (see
    :func:`~gazebot.apps.study.web.security.host_allowed`)."""
    names = list(LOOPBACK_HOSTS)
    if host in ("", "0.0.0.0", "::"):
        names += [socket.gethostname(), socket.getfqdn()]
    else:
        names.append(host)
    names += extra
    return tuple(dict.fromkeys(n.lower() for n in names if n))


def read_admin_token(path: Path) -> str:
    """The admin token in the file ``path`` (its first line); ``ValueError`` naming the file if
    it is missing, empty or too short to be a secret."""
    try:
        token = path.read_text(encoding="utf-8").strip().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path}: cannot read the admin token ({exc})") from None
    if not token or len(token[0].strip()) < 12:
        raise ValueError(f"{path}: expected an admin token of at least 12 characters")
    return token[0].strip()


def admin_token_source(
    study_root: Path, token_file: Path | None, environ: dict[str, str] | None = None
) -> tuple[str, str]:
    """(token, where it comes from): ``token_file``, else the environment variable
    ``GAZEBOT_STUDY_ADMIN_TOKEN``, else a random one written to ``DIR/admin-token`` (readable
    by its owner only). Never from the command line, where ``ps`` shows it."""
    env = os.environ if environ is None else environ
    if token_file is not None:
        return read_admin_token(token_file), str(token_file)
    if env.get(ADMIN_TOKEN_ENV, "").strip():
        token = env[ADMIN_TOKEN_ENV].strip()
        if len(token) < 12:
            raise ValueError(f"{ADMIN_TOKEN_ENV}: expected at least 12 characters")
        return token, f"${ADMIN_TOKEN_ENV}"
    path = study_root / ADMIN_TOKEN_FILE
    token = new_token(16)
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(token + "\n")
    os.chmod(path, 0o600)  # an older file may have had wider permissions
    return token, str(path)


def write_links(path: Path, base: str, links: dict[int, str]) -> None:
    """``participant,url`` per participant (the file is a key to every participant's answers:
    readable by its owner only)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w", encoding="utf-8", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["participant", "url"])
        for p in sorted(links):
            w.writerow([p, f"{base}/p/{links[p]}"])
    os.chmod(path, 0o600)


@dataclass(frozen=True)
class ConnectionLimits:
    """waitress's limits on client connections (see the module doc): ``connection_limit`` open
    connections at most, an idle connection closed after ``channel_timeout_s`` (s) without a
    byte, idle connections looked for every ``cleanup_interval_s`` (s)."""

    connection_limit: int = 1000
    channel_timeout_s: int = 20
    cleanup_interval_s: int = 5

    def waitress_options(self) -> dict[str, object]:
        """The keyword arguments of ``waitress.create_server`` that set these limits."""
        return {
            "connection_limit": self.connection_limit,
            "channel_timeout": self.channel_timeout_s,
            "cleanup_interval": self.cleanup_interval_s,
            "asyncore_use_poll": True,
        }


def raise_open_file_limit(wanted: int) -> int:
    """Raise this process's soft limit on open files to ``wanted`` (at most the hard limit):
    each connection is a file. Returns the soft limit now in force."""
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    target = wanted if hard == resource.RLIM_INFINITY else min(wanted, hard)
    if soft != resource.RLIM_INFINITY and soft < target:
        resource.setrlimit(resource.RLIMIT_NOFILE, (target, hard))
        soft = target
    if soft != resource.RLIM_INFINITY and soft < wanted:
        log.warning(
            "only %d open files allowed (hard limit): fewer than the %d connections "
            "the server accepts",
            soft,
            wanted,
        )
    return soft


def serve(
    study_dir: str,
    host: str = "127.0.0.1",
    port: int = 8000,
    threads: int = 4,
    admin_token_file: Path | None = None,
    out: TextIO | None = None,
    local_admin: bool = False,
    allowed_hosts: tuple[str, ...] = (),
    limits: ConnectionLimits = ConnectionLimits(),
) -> None:
    """Serve the rendered study in ``study_dir`` until interrupted. Writes each participant's
    link to ``DIR/participant-links.csv`` and prints where the links and the admin token are
    once the socket listens (never the token itself); ``port`` 0 picks a free port. The admin
    token: see :func:`admin_token_source`; ``local_admin``: see
    :func:`~gazebot.apps.study.web.app.create_app`; ``allowed_hosts``: host names to answer to
    besides :func:`served_host_names`; ``limits``: on client connections (slow clients)."""
    from waitress import create_server

    out = out or sys.stdout
    allowed_hosts = tuple(check_host_name(n) for n in allowed_hosts)
    root = Path(study_dir).expanduser().resolve()
    load_study(root)  # a folder that is not a study says so before a token file is written
    token, where = admin_token_source(root, admin_token_file)
    app = create_app(
        str(root),
        admin_token=token,
        local_admin=local_admin,
        allowed_hosts=served_host_names(host, allowed_hosts),
    )
    rate_limit_logs()
    # Room for every connection besides the study's files and the worker threads' own.
    raise_open_file_limit(limits.connection_limit + 64 + threads)
    server = create_server(
        app,
        host=host,
        port=port,
        threads=threads,
        ident="gazebot-study",
        max_request_body_size=MAX_BODY_BYTES,
        **limits.waitress_options(),
    )
    base = base_url(host, server.effective_port)
    study = app.config["STUDY"]
    links_path = study.root / LINKS_FILE
    write_links(links_path, base, app.extensions["gazebot_study"].links)
    print(
        f"serving {len(study.participants)} participants of {study.root} at {base}/p/TOKEN "
        f"(each participant's link in {links_path}; answers in {study.database})",
        file=out,
    )
    print(f"experimenter: {base}/admin (admin token in {where})", file=out, flush=True)
    try:
        server.run()
    finally:
        server.close()
