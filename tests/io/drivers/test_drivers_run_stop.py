"""``gazebot run`` stopped as a process manager or launch file stops a node (SIGTERM): it shuts
down like Ctrl-C and prints its summary, so a supervisor (or a test) can end a run that has no
``--duration`` and still read what the engine received."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from drivers_fakes import free_port

pytestmark = pytest.mark.zenoh


def test_sigterm_ends_gazebot_run_with_its_summary():
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[3])}
    run = subprocess.Popen(
        [sys.executable, "-m", "gazebot", "run", "--robot", "sawyer", "--no-resync",
         "--no-eye-frames", "--listen", f"tcp/127.0.0.1:{free_port()}", "--json"],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        # the node is up once it announced itself (the deadline only bounds a failing test)
        for line in run.stderr:
            if line.startswith("gazebot run: "):
                break
        run.terminate()
        out, err = run.communicate(timeout=60)
    finally:
        if run.poll() is None:
            run.kill()
            run.communicate()
    assert run.returncode == 0, err[-3000:]
    summary = json.loads(out.strip().splitlines()[-1])
    assert summary["frames"] == 0 and summary["tracking_skipped"] == 0
