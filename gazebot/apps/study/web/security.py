"""What keeps the study's web pages to their participant and their experimenter.

- Links: each participant opens ``/p/TOKEN``, ``TOKEN`` a random string (``secrets``, 144
  bits), never their number: a participant cannot open, consent or answer for another one.
- Host: a request must name this server in its ``Host`` header (the names it is served under,
  or an IP address), else 400: a DNS-rebinding page (``evil.example`` resolving to this machine)
  gets nothing.
- Sessions: the experimenter's sign-in is a random session id (a new one at each sign-in) in an
  HttpOnly, SameSite=Strict cookie, signed with the server's secret and the admin token; every
  other visitor gets a random visitor id in an HttpOnly, SameSite=Lax cookie.
- Forms: every POST carries a CSRF token, an HMAC of the server's secret, the form's scope (one
  participant's link, the sign-in form, or the experimenter's forms) and the random id of the
  cookie that POST comes with (the admin session's for the experimenter's forms, the visitor's
  otherwise): a page shows only tokens of its own visitor, and the sign-in page never the
  experimenter's. A browser's POST must also come from this site: its ``Origin`` names this
  host, or ``Origin: null`` comes with ``Sec-Fetch-Site: same-origin``, or, with neither
  header, its ``Referer`` names this host (``Referrer-Policy: same-origin`` makes browsers send
  the real ``Origin`` and ``Referer`` on the site's own forms, even over plain HTTP where they
  send no ``Sec-Fetch-*`` headers).
- Bodies: an answer is a few kB; anything over :data:`MAX_BODY_BYTES` is refused with 413
  before it is read (waitress checks ``Content-Length`` and counts chunked bodies).
- Headers: a strict Content-Security-Policy (scripts and styles by per-response nonce only, no
  framing), ``Referrer-Policy: same-origin`` (a link's token never leaks to another site) and
  ``X-Content-Type-Options: nosniff``.
- Logs: a flood of one message (waitress's "Task queue depth" under load) is rate-limited.
"""

from __future__ import annotations

import base64
import hashlib
import hmac
import ipaddress
import logging
import re
import secrets
import time
from collections.abc import Callable, Iterable
from urllib.parse import urlsplit

MAX_BODY_BYTES = 64 * 1024  # a session's answers with the longest comment are under 20 kB
LINK_TOKEN_BYTES = 18  # 144 random bits, 24 URL-safe characters
LINK_TOKEN_RE = re.compile(r"[A-Za-z0-9_-]{16,64}")
ADMIN_TOKEN_ENV = "GAZEBOT_STUDY_ADMIN_TOKEN"
LOOPBACK_HOSTS = ("localhost", "127.0.0.1", "::1")


def new_token(nbytes: int = LINK_TOKEN_BYTES) -> str:
    """A random URL-safe token (a participant's link, a session id, a secret)."""
    return secrets.token_urlsafe(nbytes)


def is_link_token(text: str) -> bool:
    """Whether ``text`` has the form of a link token (ASCII letters, digits, ``-``, ``_``)."""
    return LINK_TOKEN_RE.fullmatch(text) is not None


def _mac(secret: bytes, message: str) -> str:
    mac = hmac.new(secret, message.encode(), hashlib.sha256).digest()
    return base64.urlsafe_b64encode(mac[:24]).decode().rstrip("=")


def csrf_token(secret: bytes, scope: str, session: str) -> str:
    """The CSRF token of the forms of ``scope`` (``p:LINK``, ``login`` or ``admin``) shown to
    the holder of the cookie id ``session`` (random): stateless, so it survives a restarted
    server, and useless for another scope or another cookie."""
    return _mac(secret, f"csrf:{scope}:{session}")


#: How long an experimenter's sign-in lasts (s): a working day, so a cookie left in a shared
#: lab browser stops opening ``/admin`` by the next session.
ADMIN_SESSION_MAX_AGE_S = 12 * 3600


def admin_cookie(secret: bytes, admin_token: str, session: str, issued: int) -> str:
    """The admin session cookie of the random id ``session`` signed in at ``issued`` (Unix
    time, s): ``SESSION.ISSUED.MAC``, the MAC keyed by the server's secret over the id, the
    time and the admin token (a new token ends every session)."""
    return f"{session}.{issued}.{_mac(secret, f'admin-session:{admin_token}:{session}:{issued}')}"


def admin_session_of(
    secret: bytes,
    admin_token: str,
    cookie: str,
    now: float,
    max_age_s: float = ADMIN_SESSION_MAX_AGE_S,
) -> str | None:
    """The session id of a valid admin cookie (see :func:`admin_cookie`) issued at most
    ``max_age_s`` before ``now`` (and not in the future), else ``None``."""
    session, _, rest = cookie.partition(".")
    issued_text, _, _ = rest.partition(".")
    # ASCII digits only: str.isdigit() also accepts e.g. '²', which int() refuses.
    if not is_link_token(session) or re.fullmatch(r"[0-9]{1,12}", issued_text) is None:
        return None
    issued = int(issued_text)
    if not 0 <= now - issued <= max_age_s:
        return None
    expected = admin_cookie(secret, admin_token, session, issued)
    return session if tokens_equal(cookie, expected) else None


def tokens_equal(given: str, expected: str) -> bool:
    """Constant-time comparison of two tokens (any text)."""
    return hmac.compare_digest(given.encode("utf-8", "replace"), expected.encode())


def host_name(host: str) -> str | None:
    """The name in a ``Host`` header (lower case, no port, IPv6 without brackets); ``None``
    when it is malformed."""
    try:
        parts = urlsplit(f"//{host}")
        parts.port  # noqa: B018 - raises ValueError on a port that is not a number
    except ValueError:
        return None
    return parts.hostname or None


def host_allowed(host: str, allowed: Iterable[str]) -> bool:
    """Whether a request's ``Host`` header names this server: one of the ``allowed`` names
    (case-insensitive, any port) or an IP address. An IP address is safe to accept: a browser
    sends it only to a page of that address, while DNS rebinding needs a name of the
    attacker's."""
    name = host_name(host)
    if name is None:
        return False
    if name in {a.lower().strip("[]") for a in allowed}:
        return True
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


def _netloc(url: str) -> str:
    try:
        return urlsplit(url).netloc.lower()
    except ValueError:
        return ""


def cross_site_reason(headers: dict[str, str] | object, host: str) -> str | None:
    """Why a POST with these request headers may not come from a page of this site (``None``:
    it comes from one). ``host``: the request's ``Host`` (``name:port``). A client that sends
    neither ``Origin``, ``Sec-Fetch-Site`` nor ``Referer`` is refused: every browser sends one
    of them on a form of its own site (``Referrer-Policy: same-origin``)."""
    get = headers.get  # type: ignore[attr-defined]
    origin, site, referer = get("Origin"), get("Sec-Fetch-Site"), get("Referer")
    if site and site not in ("same-origin", "none"):
        return f"a {site} request may not post here"
    if origin == "null":
        # An opaque origin: a sandboxed frame or a no-referrer page of any site. Only a browser
        # that says the request is same-origin is believed.
        if site != "same-origin":
            return "a form from an unnamed origin (Origin: null) may not post here"
        return None
    if origin:
        if _netloc(origin) != host.lower():
            return f"a form from {origin} may not post here"
        return None
    if site:  # same-origin or none (the user's own action), said by the browser
        return None
    if not referer:
        return "a request that names no origin (no Origin, Sec-Fetch-Site or Referer) may not post"
    if _netloc(referer) != host.lower():
        return "a form from another site may not post here"
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
        # same-origin: the site's own forms carry their real Origin and Referer (checked on
        # every POST); other sites get no Referer, so a link's token never leaks.
        "Referrer-Policy": "same-origin",
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
