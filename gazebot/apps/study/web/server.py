"""``gazebot study serve``: the study's Flask app on waitress, a production WSGI server."""

from __future__ import annotations

import csv
import ipaddress
import os
import re
import socket
import sys
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
        pass
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


def serve(
    study_dir: str,
    host: str = "127.0.0.1",
    port: int = 8000,
    threads: int = 4,
    admin_token_file: Path | None = None,
    out: TextIO | None = None,
    local_admin: bool = False,
    allowed_hosts: tuple[str, ...] = (),
) -> None:
    """Serve the rendered study in ``study_dir`` until interrupted. Writes each participant's
    link to ``DIR/participant-links.csv`` and prints where the links and the admin token are
    once the socket listens (never the token itself); ``port`` 0 picks a free port. The admin
    token: see :func:`admin_token_source`; ``local_admin``: see
    :func:`~gazebot.apps.study.web.app.create_app`; ``allowed_hosts``: host names to answer to
    besides :func:`served_host_names`."""
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
    server = create_server(
        app,
        host=host,
        port=port,
        threads=threads,
        ident="gazebot-study",
        max_request_body_size=MAX_BODY_BYTES,
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
