"""The layers are enforced (``make lint`` runs lint-imports on pyproject.toml's contracts): the
real tree keeps core < io < apps, and an app imported from the core breaks the check."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("importlinter", reason="import-linter is in the [lint] extra")

REPO = Path(__file__).resolve().parents[1]
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")


def _lint_imports(root: Path) -> subprocess.CompletedProcess:
    """lint-imports with the contracts of pyproject.toml on the ``gazebot`` package under
    ``root``."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache", "--no-logo", str(REPO / "pyproject.toml")],
        capture_output=True, text=True, env=env, cwd=root, timeout=240,
    )


def test_the_tree_keeps_its_layers():
    res = _lint_imports(REPO)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "Contracts: 2 kept, 0 broken." in res.stdout


def test_an_app_imported_from_the_core_breaks_the_layers(tmp_path):
    shutil.copytree(REPO / "gazebot", tmp_path / "gazebot",
                    ignore=shutil.ignore_patterns("__pycache__"))
    phases = tmp_path / "gazebot" / "core" / "phases" / "__init__.py"
    phases.write_text(phases.read_text() + "\nimport gazebot.apps.sim  # noqa: E402\n")
    res = _lint_imports(tmp_path)
    assert res.returncode == 1, res.stdout + res.stderr
    assert "core < io < apps BROKEN" in res.stdout
    assert "gazebot.core.phases -> gazebot.apps.sim" in res.stdout
