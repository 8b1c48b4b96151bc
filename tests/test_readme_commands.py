"""Every command block of the README runs as written: the blocks are read from README.md (never
copied here) and run by bash from the repository root, relative paths and all.

One line is left out: ``make test``, the command running this very test. The blocks use the
README's venv (``.venv``, which ``make test`` builds), so they run only from it.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
README = REPO / "README.md"
FENCE = re.compile(r"^```bash\n(.*?)^```", re.S | re.M)
#: Lines a test cannot run: the command that runs the tests.
NOT_RUN = re.compile(r"^\s*make test\b")
#: What one block may take on a busy 2-core machine (an install of every extra is the longest).
BLOCK_TIMEOUT_S = 1500


def readme_blocks() -> list[str]:
    """The README's ``bash`` blocks, in order."""
    return FENCE.findall(README.read_text(encoding="utf-8"))


def _block_id(block: str) -> str:
    first = next(line for line in block.splitlines() if line.strip() and not line.startswith("#"))
    return first.split("#")[0].strip()[:60]


def test_the_readme_has_its_command_blocks():
    blocks = readme_blocks()
    assert len(blocks) >= 5
    assert any("make demo" in b for b in blocks) and any("make test" in b for b in blocks)


@pytest.mark.slow
@pytest.mark.timeout(BLOCK_TIMEOUT_S + 60)
@pytest.mark.parametrize("block", readme_blocks(), ids=_block_id)
def test_a_readme_command_block_runs_as_written(block, tmp_path):
    if Path(sys.prefix).resolve() != (REPO / ".venv").resolve():
        pytest.skip("the README's commands use .venv (the one `make test` builds); this run's "
                    f"Python is {sys.prefix}")
    script = "\n".join(line for line in block.splitlines() if not NOT_RUN.match(line))
    env = {
        **os.environ,
        # `~` in a block is a scratch home: an install block must not touch the user's own.
        "HOME": str(tmp_path),
        "PIP_CACHE_DIR": os.environ.get("PIP_CACHE_DIR", str(Path.home() / ".cache" / "pip")),
        "PYTHONPATH": str(REPO),
    }
    proc = subprocess.Popen(
        ["bash", "-euo", "pipefail", "-c", script], cwd=REPO, env=env, start_new_session=True,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )
    try:
        out, _ = proc.communicate(timeout=BLOCK_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        pytest.fail(f"the block did not finish in {BLOCK_TIMEOUT_S} s:\n{out[-4000:]}")
    finally:
        try:  # whatever the block left in the background
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    assert proc.returncode == 0, f"exit {proc.returncode}:\n{out[-4000:]}"
    assert "Traceback" not in out, out[-4000:]
