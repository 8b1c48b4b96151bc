"""The phase detector keeps no phase of its own: it reads the one handover state and reports the
boundaries the tracking shows beyond it; a phase the robot's events set is the one it follows."""

from __future__ import annotations

import math

from gazebot.core.phases import OnlineDetector
from gazebot.core.phases.synthetic import SyntheticOptions, generate
from gazebot.core.types import Event, EventKind, Phase

PHASE_KINDS = (
    EventKind.REACH_STARTED,
    EventKind.TRANSFER_STARTED,
    EventKind.RETREAT_STARTED,
    EventKind.HANDOVER_DONE,
)


def _handover(seed: int = 4):
    case = generate(seed, SyntheticOptions(rate=100))
    return case.truth[0], list(case.trajectory.frames())


def _holds_a_phase(obj: object) -> list[str]:
    return [name for name, value in vars(obj).items() if isinstance(value, Phase)]


def test_the_detector_holds_no_phase_through_a_handover():
    _, frames = _handover()
    det = OnlineDetector()
    for f in frames:
        det.update_all(f)
        assert _holds_a_phase(det.detector) == []
    assert det.phase is Phase.DONE and not hasattr(det.detector, "phase")


def test_a_reach_the_robot_started_still_gets_the_givers_start_and_the_earlier_one_wins():
    h, frames = _handover()
    det = OnlineDetector()
    robot_t = h.reach_start + 0.15  # the robot sets off just after the giver
    told = False
    reported = []
    start = math.nan
    for f in frames:
        if not told and f.t >= robot_t:
            det.state.apply(Event(EventKind.ROBOT_REACH_STARTED, robot_t, robot_t,
                                  {"planned_duration": 1.0}))
            told = True
            # A reach only the robot started: no tracking estimate of its end yet.
            assert det.phase is Phase.REACH and math.isnan(det.expected_phase_end)
        new = [e for e in det.update_all(f) if e.kind in PHASE_KINDS]
        if new and not reported:
            start = det.phase_start
        reported += new
    assert [e.kind for e in reported] == list(PHASE_KINDS)
    giver = reported[0]
    # Seen while the state was already in the robot's reach: reported all the same.
    assert giver.detected_at > robot_t
    assert giver.t < robot_t and giver.info["handover"] == 0 and start == giver.t
    # The giver's earlier start is the reach's: one handover, its source the tracking.
    assert det.handover == 0 and det.state.ignored == 0


def test_a_transfer_the_grasp_started_is_the_one_the_detector_ends():
    h, frames = _handover()
    det = OnlineDetector()
    grasp = h.transfer_start + 0.05
    told = False
    reported = []
    for f in frames:
        if not told and f.t >= grasp and det.phase is Phase.REACH:
            det.state.apply(Event(EventKind.ROBOT_GRASPED, f.t, f.t))
            told = True
            assert det.phase is Phase.TRANSFER and det.expected_phase_end >= f.t
        reported += [e for e in det.update_all(f) if e.kind in PHASE_KINDS]
    assert told
    kinds = [e.kind for e in reported]
    # The detector reports no transfer start of its own once the state is in the transfer.
    assert kinds.count(EventKind.TRANSFER_STARTED) <= 1
    after = [e.kind for e in reported if e.detected_at >= grasp]
    assert EventKind.TRANSFER_STARTED not in after
    assert after[-2:] == [EventKind.RETREAT_STARTED, EventKind.HANDOVER_DONE]
    assert det.handover == 0 and det.phase is Phase.DONE
