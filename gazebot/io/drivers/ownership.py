"""One engine per robot: ownership of a robot's command topics by a liveliness token.

An engine that wants to command the robot of a namespace declares a *claim*, the token
``@gazebot_owner/<domain>/<namespace, mangled>/<start ns>/<zid>/<node>``, and keeps it while it
runs; Zenoh removes it when the engine's session ends, even when the process is killed. The
claim with the earliest start (then the smallest zid and node name) owns the robot; the others
are rivals: refused (they exit) or on standby (they take over when the owner's claim vanishes).
The robot side watches the same tokens and reports competing engines. Start times come from the
engines' wall clocks: with clocks skewed by more than the gap between two starts, the
first-come order may be wrong, but every party still agrees on one owner.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from gazebot.io.drivers.rmw.names import Names, check_node_name, demangle, mangle

if TYPE_CHECKING:
    import zenoh

log = logging.getLogger("gazebot.io.drivers")

OWNER_SPACE = "@gazebot_owner"


@dataclass(frozen=True, order=True)
class Claim:
    """One engine's claim on a robot; claims order by who owns first (``start_ns``, then
    ``zid``, then ``node``).

    Attributes:
        start_ns: When the engine claimed the robot (ns since the epoch, its wall clock).
        zid: The engine's Zenoh session id (hex).
        node: The engine's node name.
        namespace: The robot's namespace.
        domain_id: The ROS domain.
    """

    start_ns: int
    zid: str
    node: str
    namespace: str = "/"
    domain_id: int = 0

    def key(self) -> str:
        """The claim's liveliness token key."""
        return (f"{OWNER_SPACE}/{self.domain_id}/{mangle(self.namespace)}/{self.start_ns}/"
                f"{self.zid}/{self.node}")

    @classmethod
    def parse(cls, key: str) -> Claim:
        """The claim of a token key; ``ValueError`` saying what is wrong."""
        parts = key.split("/")
        if len(parts) != 6 or parts[0] != OWNER_SPACE:
            raise ValueError(f"not an ownership token: {key[:200]!r}")
        _, domain, ns, start, zid, node = parts
        if not (domain.isdigit() and len(domain) <= 3 and start.isdigit() and len(start) <= 20):
            raise ValueError(f"non-numeric domain or start in {key[:200]!r}")
        if not zid or len(zid) > 32 or any(c not in "0123456789abcdef" for c in zid):
            raise ValueError(f"bad zid {zid[:40]!r} in an ownership token")
        check_node_name(node)
        return cls(int(start), zid, node, demangle(ns), int(domain))

    def __str__(self) -> str:
        return f"{self.node} (session {self.zid})"


class OwnershipWatch:
    """The claims alive on a robot's namespace, from a liveliness subscriber (thread-safe).

    Args:
        session: An open Zenoh session.
        names: The robot's namespace and domain.
        on_change: Called with the claims alive after each change (on Zenoh's thread).
    """

    def __init__(self, session: zenoh.Session, names: Names,
                 on_change: Callable[[list[Claim]], None] | None = None) -> None:
        self.names = names
        self.on_change = on_change
        self.bad_tokens = 0
        self._lock = threading.Lock()
        self._claims: dict[str, Claim] = {}
        self._gone: set[str] = set()  # keys seen vanishing (a late query answer is stale)
        self.prefix = f"{OWNER_SPACE}/{names.domain_id}/{mangle(names.namespace)}"
        self._sub = session.liveliness().declare_subscriber(
            f"{self.prefix}/**", self._on_token, history=True)

    def _on_token(self, sample: zenoh.Sample) -> None:
        import zenoh

        key = str(sample.key_expr)
        try:
            claim = Claim.parse(key)
        except ValueError:
            with self._lock:
                self.bad_tokens += 1
            return
        with self._lock:
            if sample.kind == zenoh.SampleKind.PUT:
                self._claims[key] = claim
                self._gone.discard(key)
            else:
                self._claims.pop(key, None)
                self._gone.add(key)
            claims = sorted(self._claims.values())
        if self.on_change is not None:
            try:
                self.on_change(claims)
            except Exception:
                log.exception("ownership callback failed")

    def claims(self) -> list[Claim]:
        """Claims alive, the owner first."""
        with self._lock:
            return sorted(self._claims.values())

    def owner(self) -> Claim | None:
        claims = self.claims()
        return claims[0] if claims else None

    def undeclare(self) -> None:
        try:
            self._sub.undeclare()
        except Exception:  # the session may already be closed
            pass


class Ownership(OwnershipWatch):
    """An engine's claim on the robot of ``names.namespace`` and the watch of the others'.

    Args:
        session: The engine's open Zenoh session.
        names: The robot's namespace and domain.
        node: The engine's node name.
        clock_ns: Wall clock (ns since the epoch) giving the claim's start.
    """

    def __init__(self, session: zenoh.Session, names: Names, node: str,
                 clock_ns: Callable[[], int] = time.time_ns) -> None:
        super().__init__(session, names)
        self.session = session
        self.claim = Claim(clock_ns(), str(session.info.zid()), check_node_name(node),
                           names.namespace, names.domain_id)
        self._token: zenoh.LivelinessToken | None = None

    def declare(self, timeout: float = 0.5) -> list[Claim]:
        """Declare the claim and ask the bus for the claims alive (waiting up to ``timeout``
        s for the answers); returns them, the owner first (this one included)."""
        if self._token is None:
            self._token = self.session.liveliness().declare_token(self.claim.key())
        found = {self.claim}
        for reply in self.session.liveliness().get(f"{self.prefix}/**", timeout=timeout):
            if reply.ok is None:
                continue
            try:
                found.add(Claim.parse(str(reply.ok.key_expr)))
            except ValueError:
                continue
        with self._lock:
            for claim in found:
                if claim.key() not in self._gone:
                    self._claims.setdefault(claim.key(), claim)
        return self.claims()

    def rivals(self) -> list[Claim]:
        """The other engines' claims alive, the earliest first."""
        return [c for c in self.claims() if c != self.claim]

    def is_owner(self) -> bool:
        """Whether this engine's claim is the earliest alive (``False`` before
        :meth:`declare`)."""
        if self._token is None:
            return False
        rivals = self.rivals()
        return not rivals or self.claim < rivals[0]

    def undeclare(self) -> None:
        """Withdraw the claim and stop watching; idempotent."""
        token, self._token = self._token, None
        if token is not None:
            try:
                token.undeclare()
            except Exception:
                pass
        super().undeclare()
