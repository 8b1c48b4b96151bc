"""``gazebot study serve``: the study's Flask app on waitress, a production WSGI server."""

from __future__ import annotations

import secrets
import socket
import sys
from typing import TextIO

from gazebot.study.web.app import create_app


def base_url(host: str, port: int) -> str:
    """The address to print for a server on ``host``: a wildcard address (all interfaces) is
    not one a browser can open, so the machine's name stands for it."""
    if host in ("", "0.0.0.0", "::"):
        host = socket.gethostname()
    shown = f"[{host}]" if ":" in host else host
    return f"http://{shown}:{port}"


def serve(
    study_dir: str,
    host: str = "127.0.0.1",
    port: int = 8000,
    threads: int = 4,
    admin_token: str | None = None,
    out: TextIO | None = None,
    local_admin: bool = True,
) -> None:
    """Serve the rendered study in ``study_dir`` until interrupted. Prints the participant and
    experimenter addresses (with the admin token) once the socket listens; ``port`` 0 picks a
    free port. ``local_admin``: see :func:`~gazebot.study.web.app.create_app`."""
    from waitress import create_server

    out = out or sys.stdout
    token = admin_token or secrets.token_urlsafe(16)
    app = create_app(study_dir, admin_token=token, local_admin=local_admin)
    server = create_server(app, host=host, port=port, threads=threads, ident="gazebot-study")
    base = base_url(host, server.effective_port)
    study = app.config["STUDY"]
    print(
        f"serving {len(study.participants)} participants of {study.root} at {base}/p/N "
        f"(answers in {study.database})",
        file=out,
    )
    print(f"experimenter: {base}/admin?token={token}", file=out, flush=True)
    try:
        server.run()
    finally:
        server.close()
