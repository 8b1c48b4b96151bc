"""What the engine node keeps stays bounded over a long run (issue 30, item 7: memory over a
soak): counts, not timings."""

from __future__ import annotations

from gazebot.core.runtime import GazeLoop
from gazebot.io.drivers.engine_node import MAX_WARNINGS, EngineNode, EngineNodeConfig
from gazebot.io.drivers.tracking_source import Rival
from tests.io.drivers.drivers_fakes import FakeEngine
from tests.io.drivers.test_drivers_eyes_presence import Clock, MemoryDriver


class RestartingTracker(MemoryDriver):
    """A robot whose tracker comes back as a new source at every tick (a tracker restarted
    over and over beside a stale owner): each is a new rival, so a new warning."""

    def __init__(self) -> None:
        super().__init__()
        self.restarts = 0

    def tracking_rivals(self, new_only: bool = False) -> list[Rival]:
        if new_only:
            self.restarts += 1
        return [Rival(f"tracker (session {self.restarts})", "giver_hand", "tracker", 1)]


def test_the_node_keeps_the_latest_warnings_only():
    clock = Clock()
    drv = RestartingTracker()
    cfg = EngineNodeConfig(heartbeat_period=0.5, resync=False)
    node = EngineNode(GazeLoop(FakeEngine()), drv, cfg, warn=lambda _: None, clock=clock)
    node.start()
    for k in range(5 * MAX_WARNINGS):
        clock.now = 0.1 * k
        node.tick()
    assert drv.restarts == 5 * MAX_WARNINGS
    assert len(node.warnings) == MAX_WARNINGS
    assert f"session {drv.restarts})" in node.warnings[-1]  # the latest are the ones kept
    assert all(len(s.info["warnings"]) <= MAX_WARNINGS for s in drv.statuses)
    # every one was still reported as an event
    assert len([e for e in drv.events if e.kind == "competing_tracking"]) == 5 * MAX_WARNINGS
