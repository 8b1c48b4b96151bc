"""An infeasible STL reach in ``gazebot demo``: the robot stops and says so (the seed's failure
feedback, 3.2), and the run ends then with its own exit status, not after the full 30 s cut as
an unfinished handover."""

from __future__ import annotations

import json

from gazebot.apps.cli import main
from gazebot.apps.cli.demo import EXIT_INFEASIBLE
from gazebot.apps.controllers import INFEASIBLE_MESSAGE


def test_infeasible_stl_reach_ends_once_the_robot_stopped_with_its_own_exit_status(
    tmp_path, capsys
):
    argv = ["demo", "--controller", "stl", "--reach-time", "0.3", "--width", "160",
            "--height", "120", "--out", str(tmp_path), "--no-progress", "--json"]
    assert main(argv) == EXIT_INFEASIBLE == 3
    captured = capsys.readouterr()
    summary = json.loads(captured.out)
    assert summary["reach_infeasible"] and not summary["completed"]
    stopped = next(e for e in summary["robot_events"] if e["kind"] == "robot_reach_infeasible")
    # Simulated time: the feedback stays on screen a few seconds, then the video ends (it ran
    # to the 30 s cut before).
    assert stopped["t"] + 3.0 < summary["duration_s"] < 12.0
    assert INFEASIBLE_MESSAGE in captured.err and "the robot stopped (exit 3)" in captured.err
    assert "did not finish" not in captured.out + captured.err
