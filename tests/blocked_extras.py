"""Run Python as on the core install (``pip install gazebot``, no extras): a subprocess whose
import system refuses every package that only an extra installs
(:data:`gazebot.apps.cli.extras.EXTRA_OF_MODULE`), as if it were not installed."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

_PRELUDE = """
import importlib.abc, sys
from gazebot.apps.cli.extras import EXTRA_OF_MODULE

class _NoExtras(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] in EXTRA_OF_MODULE:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None

assert not set(EXTRA_OF_MODULE) & set(sys.modules), "an extra was imported before the block"
sys.meta_path.insert(0, _NoExtras())
"""


def run_without_extras(code: str, *, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``code`` run by this interpreter with the extras' packages blocked (stdout, stderr
    captured as text)."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    return subprocess.run([sys.executable, "-c", _PRELUDE + code], capture_output=True,
                          text=True, env=env, cwd=cwd, timeout=240)


def gazebot_without_extras(*argv: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """The ``gazebot`` command line with ``argv``, run without the extras."""
    code = f"from gazebot.apps.cli import main\nraise SystemExit(main({list(argv)!r}))\n"
    return run_without_extras(code, cwd=cwd)
