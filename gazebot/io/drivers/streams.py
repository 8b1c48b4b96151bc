"""One stream per publisher GID (issue 30): a GID is public (the hash of the publisher's
liveliness token), so anyone may put samples with it. The sequence numbers of one publisher's
attachments go forward one by one; a GID whose numbers go back carries a second stream, a copy.
Neither stream can be told from the other without credentials, so both are refused while the
copy lasts: the GID is *suspect* until ``hold`` s after its numbers last went back. Numbers
go back only when the streams interleave, so a copy arriving more than ``hold`` s after the
real publisher's last sample is taken; credentials (an authenticated bus) close that gap.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

#: GIDs remembered at most (only GIDs of announced publishers are checked).
MAX_GIDS = 1024


class SequenceGuard:
    """Checks that each GID's sequence numbers go forward (thread-safe).

    Args:
        hold: A GID stays suspect this long (s) after its numbers last went back.
        clock: Monotonic clock (s).
    """

    def __init__(self, hold: float = 1.0, clock: Callable[[], float] = time.monotonic) -> None:
        self.hold = float(hold)
        self.clock = clock
        self._lock = threading.Lock()
        self._last: dict[bytes, int] = {}
        self._suspect: dict[bytes, float] = {}  # GID -> suspect until (monotonic s)

    def check(self, gid: bytes, seq: int) -> str | None:
        """``None`` when a sample numbered ``seq`` may be used, else why not."""
        now = self.clock()
        with self._lock:
            if len(self._last) > MAX_GIDS:
                self._last.clear()
            last = self._last.get(gid)
            self._last[gid] = seq
            if last is not None and seq <= last:
                self._suspect[gid] = now + self.hold
                return f"sequence number {seq} after {last}: a second stream uses this GID"
            until = self._suspect.get(gid)
            if until is not None:
                if now < until:
                    return "this GID carried a second stream lately"
                del self._suspect[gid]
        return None

    def forget(self, gid: bytes) -> None:
        """Forget ``gid`` (its publisher went away)."""
        with self._lock:
            self._last.pop(gid, None)
            self._suspect.pop(gid, None)
