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
from gazebot.io.drivers.rmw.node import undeclare_quietly

if TYPE_CHECKING:
    import zenoh

    from gazebot.io.drivers.rmw.graph import Graph

log = logging.getLogger("gazebot.io.drivers")

OWNER_SPACE = "@gazebot_owner"
#: A claim seen within this many seconds of the owner being settled on is ordered by its start
#: (engines starting together agree); a later one never pre-empts the owner.
SETTLE = 1.0
#: A claim whose engine node is not in the graph this long after it was seen is forged.
GRACE = 1.0


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
    """The claims alive on a robot's namespace, from a liveliness subscriber, and the owner they
    settle on (thread-safe).

    Args:
        session: An open Zenoh session.
        names: The robot's namespace and domain.
        on_change: Called with the claims alive after each change (on Zenoh's thread).
        graph: The ROS graph a claim's engine node must be in to count (``None``: every claim
            counts, as before issue 30).
        settle: See :data:`SETTLE`.
        grace: See :data:`GRACE`.
        clock: Monotonic clock (s).
    """

    def __init__(self, session: zenoh.Session, names: Names,
                 on_change: Callable[[list[Claim]], None] | None = None, *,
                 graph: Graph | None = None, settle: float = SETTLE, grace: float = GRACE,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.names = names
        self.on_change = on_change
        self.graph = graph
        self.settle = float(settle)
        self.grace = float(grace)
        self.clock = clock
        self.bad_tokens = 0
        self._lock = threading.Lock()
        self._claims: dict[str, Claim] = {}
        self._seen: dict[str, float] = {}  # claim key -> when first seen (monotonic)
        self._gone: set[str] = set()  # keys seen vanishing (a late query answer is stale)
        self._owner: Claim | None = None
        self._owner_since = 0.0
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
                self._add(key, claim)
                self._gone.discard(key)
            else:
                self._claims.pop(key, None)
                self._seen.pop(key, None)
                self._gone.add(key)
            claims = sorted(self._claims.values())
        self.owner()  # settle on an owner as claims come and go, not only when asked
        if self.on_change is not None:
            try:
                self.on_change(claims)
            except Exception:
                log.exception("ownership callback failed")

    def _add(self, key: str, claim: Claim) -> None:
        """Record a claim alive (under the lock)."""
        self._claims[key] = claim
        self._seen.setdefault(key, self.clock())

    def _backed(self, claim: Claim) -> bool:
        """Whether the claim's engine node is in the graph."""
        if self.graph is None or self._is_own(claim):
            return True
        return any(e.zid == claim.zid and e.node == claim.node
                   for e in self.graph.nodes(claim.namespace))

    def _is_own(self, claim: Claim) -> bool:
        """Whether ``claim`` is this party's own (its node is known to exist)."""
        return False

    def claims(self) -> list[Claim]:
        """Claims alive, the owner first."""
        owner = self.owner()
        with self._lock:
            rest = sorted(c for c in self._claims.values() if c != owner)
        return [owner, *rest] if owner is not None else rest

    def forged(self) -> list[Claim]:
        """Claims alive whose engine node has not been in the graph within ``grace`` s."""
        now = self.clock()
        with self._lock:
            items = [(c, self._seen.get(k, now)) for k, c in self._claims.items()]
        return sorted(c for c, seen in items if now - seen > self.grace and not self._backed(c))

    def owner(self) -> Claim | None:
        """The claim that owns the robot: the owner settled on while its claim lives (a claim
        seen within ``settle`` s of that choice and starting earlier takes its place), else the
        earliest claim whose engine is in the graph; ``None`` while none is, or while an
        earlier claim still waits for its node (up to ``grace`` s)."""
        now = self.clock()
        with self._lock:
            items = [(c, self._seen.get(k, now)) for k, c in self._claims.items()]
            owner, since = self._owner, self._owner_since
        live = sorted(items)
        if owner is not None and any(c == owner for c, _ in live):
            earlier = [c for c, seen in live if c < owner and seen <= since + self.settle
                       and self._backed(c)]
            if not earlier:
                return owner
            new: Claim | None = earlier[0]
        else:
            new = None
            for c, seen in live:
                if self._backed(c):
                    new = c
                    break
                if now - seen <= self.grace:  # its node may still be on its way
                    return None
        with self._lock:
            if new != self._owner:
                self._owner, self._owner_since = new, now
            return self._owner

    def undeclare(self) -> None:
        """Stop watching the claims (undeclare the liveliness subscriber; quiet if the session is
        closed)."""
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
                 clock_ns: Callable[[], int] = time.time_ns, *, graph: Graph | None = None,
                 settle: float = SETTLE, grace: float = GRACE,
                 clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__(session, names, graph=graph, settle=settle, grace=grace, clock=clock)
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
                if claim.key() not in self._gone and claim.key() not in self._claims:
                    self._add(claim.key(), claim)
        # An earlier claim whose node is not seen yet: wait (up to ``grace``) to know whether
        # it is an engine or a forgery.
        end = self.clock() + self.grace + 0.1
        while self.owner() is None and self.clock() < end:
            time.sleep(0.02)
        return self.claims()

    def _is_own(self, claim: Claim) -> bool:
        # Zenoh may call back before __init__ has set the claim
        return claim == getattr(self, "claim", None) and getattr(self, "_token", None) is not None

    def rivals(self) -> list[Claim]:
        """The other engines' claims alive, the owner first."""
        return [c for c in self.claims() if c != self.claim]

    def is_owner(self) -> bool:
        """Whether this engine's claim owns the robot (:meth:`OwnershipWatch.owner`;
        ``False`` before :meth:`declare`)."""
        return self._token is not None and self.owner() == self.claim

    def undeclare(self) -> None:
        """Withdraw the claim and stop watching; idempotent."""
        token, self._token = self._token, None
        undeclare_quietly(token)
        super().undeclare()
