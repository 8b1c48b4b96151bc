"""What keeps the study's web pages to their participant and their experimenter.

- Links: each participant opens ``/p/TOKEN``, ``TOKEN`` a random string (``secrets``, 144
  bits), never their number: a participant cannot open, consent or answer for another one.
- Forms: every POST carries a CSRF token, an HMAC of the server's secret and the form's scope
  (one participant's link, or the experimenter), and a browser's POST must come from this site
  (its ``Origin``, or its ``Sec-Fetch-Site`` where ``Referrer-Policy: no-referrer`` makes the
  browser send ``Origin: null``).
- Bodies: an answer is a few kB; anything over :data:`MAX_BODY_BYTES` is refused with 413
  before it is read (waitress checks ``Content-Length`` and counts chunked bodies).
- Headers: a strict Content-Security-Policy (scripts and styles by per-response nonce only, no
  framing), ``Referrer-Policy: no-referrer`` (a link's token never leaks to another site) and
  ``X-Content-Type-Options: nosniff``.
- Logs: a flood of one message (waitress's "Task queue depth" under load) is rate-limited.
"""

from __future__ import annotations

import base64
import hashlib
import hmac
import logging
import re
import secrets
import time
from collections.abc import Callable
from urllib.parse import urlsplit

MAX_BODY_BYTES = 64 * 1024  # a session's answers with the longest comment are under 20 kB
LINK_TOKEN_BYTES = 18  # 144 random bits, 24 URL-safe characters
LINK_TOKEN_RE = re.compile(r"[A-Za-z0-9_-]{16,64}")
ADMIN_TOKEN_ENV = "GAZEBOT_STUDY_ADMIN_TOKEN"


def new_token(nbytes: int = LINK_TOKEN_BYTES) -> str:
    """A random URL-safe token (a participant's link, a secret)."""
    return secrets.token_urlsafe(nbytes)


def is_link_token(text: str) -> bool:
    """Whether ``text`` has the form of a link token (ASCII letters, digits, ``-``, ``_``)."""
    return LINK_TOKEN_RE.fullmatch(text) is not None


def csrf_token(secret: bytes, scope: str) -> str:
    """The CSRF token of the forms of ``scope`` (``p:LINK`` or ``admin``): stateless, so it
    survives a restarted server, and useless for any other scope."""
    mac = hmac.new(secret, f"csrf:{scope}".encode(), hashlib.sha256).digest()
    return base64.urlsafe_b64encode(mac[:24]).decode().rstrip("=")


def tokens_equal(given: str, expected: str) -> bool:
    """Constant-time comparison of two tokens (any text)."""
    return hmac.compare_digest(given.encode("utf-8", "replace"), expected.encode())


def cross_site_reason(headers: dict[str, str] | object, host: str) -> str | None:
    """Why a POST with these request headers is not from this site (``None``: it is, or the
    client is not a browser). ``host``: the request's ``Host`` (``name:port``)."""
    get = headers.get  # type: ignore[attr-defined]
    origin = get("Origin")
    if origin and origin != "null":
        netloc = urlsplit(origin).netloc
        if netloc.lower() != host.lower():
            return f"a form from {origin} may not post here"
        return None
    site = get("Sec-Fetch-Site")
    if site and site not in ("same-origin", "none"):
        return f"a {site} request may not post here"
    return None


def security_headers(nonce: str) -> dict[str, str]:
    """Headers of every response; ``nonce``: this response's script and style nonce."""
    csp = (
        "default-src 'none'; "
        f"script-src 'nonce-{nonce}'; style-src 'nonce-{nonce}'; "
        "media-src 'self'; img-src 'self'; form-action 'self'; "
        "frame-ancestors 'none'; base-uri 'none'"
    )
    return {
        "Content-Security-Policy": csp,
        "Referrer-Policy": "no-referrer",
        "X-Content-Type-Options": "nosniff",
        "X-Frame-Options": "DENY",
        "Cross-Origin-Opener-Policy": "same-origin",
        "Cross-Origin-Resource-Policy": "same-origin",
    }


class RateLimitFilter(logging.Filter):
    """Lets one record of each message template through per ``interval_s``; the next one let
    through says how many were dropped in between. ``clock``: seconds (monotonic)."""

    def __init__(self, interval_s: float = 10.0, clock: Callable[[], float] = time.monotonic):
        super().__init__()
        self.interval_s = interval_s
        self.clock = clock
        self._last: dict[tuple[str, str], float] = {}
        self._dropped: dict[tuple[str, str], int] = {}

    def filter(self, record: logging.LogRecord) -> bool:
        key = (record.name, str(record.msg))
        now = self.clock()
        last = self._last.get(key)
        if last is not None and now - last < self.interval_s:
            self._dropped[key] = self._dropped.get(key, 0) + 1
            return False
        self._last[key] = now
        dropped = self._dropped.pop(key, 0)
        if dropped:
            record.msg = f"{record.msg} ({dropped} more like this in the last {now - last:.0f} s)"
        return True


def rate_limit_logs(names: tuple[str, ...] = ("waitress", "waitress.queue"), interval_s=10.0):
    """Install one :class:`RateLimitFilter` on each named logger (a logger's filters see only
    its own records, so a child logger needs its own); returns the filter."""
    flt = RateLimitFilter(interval_s)
    for name in names:
        logger = logging.getLogger(name)
        for old in [f for f in logger.filters if isinstance(f, RateLimitFilter)]:
            logger.removeFilter(old)
        logger.addFilter(flt)
    return flt
